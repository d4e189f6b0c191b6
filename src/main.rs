//! The `goldray` binary: a thin command-line layer (`cli/`) over the `goldray` library.

mod cli;

fn main() -> std::process::ExitCode {
    cli::main()
}
