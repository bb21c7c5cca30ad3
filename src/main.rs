//! The `scenefit` command: parses the command line and runs it; a user's
//! mistake exits with code 2 and one line, success with 0.

fn main() {
    std::process::exit(scenefit::cli::main());
}
