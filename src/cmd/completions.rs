//! `raypipe completions`: print a shell completion script (bash, zsh, fish, elvish or powershell) on stdout.

use super::prelude::*;

/// The options of `raypipe completions`.
#[derive(clap::Args, Clone)]
pub struct Args {
    /// The shell.
    #[arg(value_enum)]
    pub shell: clap_complete::Shell,
}

/// Runs `raypipe completions`.
pub fn run(a: Args) -> Result<Outcome, String> {
    let Args { shell } = a;
    use clap::CommandFactory;
    clap_complete::generate(shell, &mut crate::Cli::command(), "raypipe", &mut std::io::stdout());
    Ok(Outcome::Pass)
}
