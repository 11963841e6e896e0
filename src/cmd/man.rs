//! `raypipe man`: print the man page (roff) of raypipe, or of one of its commands, on stdout.

use super::prelude::*;

/// The options of `raypipe man`.
#[derive(clap::Args, Clone)]
pub struct Args {
    /// A command (e.g. verify); none: the page of raypipe itself, which lists them.
    pub command: Option<String>,
}

/// Runs `raypipe man`.
pub fn run(a: Args) -> Result<Outcome, String> {
    let Args { command } = a;
    use clap::CommandFactory;
    let mut cli = crate::Cli::command();
    cli.build();
    let page = match command {
        None => cli,
        Some(name) => {
            let names: Vec<String> = cli.get_subcommands().map(|c| c.get_name().to_string()).collect();
            let sub = cli
                .find_subcommand(&name)
                .ok_or_else(|| format!("raypipe man: no command '{name}'; the commands: {}", names.join(", ")))?;
            // the page of `raypipe NAME` is named raypipe-NAME(1)
            sub.clone().name(format!("raypipe-{name}")).bin_name(format!("raypipe {name}"))
        }
    };
    let mut roff = Vec::new();
    clap_mangen::Man::new(page).render(&mut roff).map_err(|e| e.to_string())?;
    std::io::Write::write_all(&mut std::io::stdout(), &roff).map_err(|e| e.to_string())?;
    Ok(Outcome::Pass)
}
