//! The `marsupial` command-line tool ([`marsupial::cli::run`]): a crate with robots of
//! its own builds the same command serving them with [`marsupial::cli::run_with`].

fn main() -> std::process::ExitCode {
    marsupial::cli::run()
}
