//! The `marsupial` command-line tool.

use clap::{Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;

/// Reactive vision-based docking: validate profiles, run perception, docking runs and
/// trial campaigns in the built-in simulator.
#[derive(Parser, Debug)]
#[command(name = "marsupial", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Validate profile and scenario files.
    ///
    /// Prints `ok FILE` for each valid file. For each invalid file prints every problem
    /// as `FILE:LINE: FIELD.PATH: what was expected`, and exits with status 1.
    Check {
        /// Files to check (TOML).
        #[arg(required = true, value_name = "FILE")]
        files: Vec<PathBuf>,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
        Command::Check { files } => {
            let bad = marsupial::cli::check::run(&files, &mut std::io::stdout(), &mut std::io::stderr());
            if bad == 0 { ExitCode::SUCCESS } else { ExitCode::FAILURE }
        }
    }
}
