//! The `goldray` binary: a thin command-line layer (`cli/`) over the `goldray` library.

mod allocator;
mod cli;

#[global_allocator]
static ALLOCATOR: allocator::HugePageBlocks = allocator::HugePageBlocks;

fn main() -> std::process::ExitCode {
    cli::main()
}
