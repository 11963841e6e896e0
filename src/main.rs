//! The `raypipe` command line: parses it and runs the command (`cmd/`, one file each).

mod cmd;

use clap::Parser;
use std::process::ExitCode;

/// Large blocks (the batch columns) at staggered page offsets, so that a kernel's columns do
/// not share cache sets (see [`datapath::alloc`]).
#[global_allocator]
static ALLOC: datapath::alloc::Staggered = datapath::alloc::Staggered;

/// The command line.
#[derive(Parser)]
#[command(
    name = "raypipe",
    version,
    about = "Bit-accurate ray-tracing datapath models judged against a golden f64 reference"
)]
pub struct Cli {
    #[command(subcommand)]
    cmd: Option<cmd::Cmd>,
}

/// Parses the command line (text only: the manifest records it) and runs the command.
fn run() -> Result<raypipe::Outcome, String> {
    if let Some(a) = std::env::args_os().find(|a| a.to_str().is_none()) {
        return Err(format!(
            "argument {a:?} is not valid UTF-8; raypipe records its command line and needs text arguments"
        ));
    }
    cmd::dispatch(Cli::parse().cmd)
}

fn main() -> ExitCode {
    // a closed stdout pipe (`raypipe … | head`) ends the process quietly, as it does any Unix
    // tool, instead of failing a print (Rust ignores SIGPIPE by default, so println! panics)
    #[cfg(unix)]
    // SAFETY: restoring the default disposition of one signal before any thread starts
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    // an interrupted run removes its temporary files and directories (exit 130, as a shell does)
    let _ = ctrlc::set_handler(|| {
        vectors::outdir::remove_partials();
        eprintln!("interrupted: removed the partial output");
        std::process::exit(130);
    });
    match run() {
        Ok(o) => ExitCode::from(o as u8),
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}
