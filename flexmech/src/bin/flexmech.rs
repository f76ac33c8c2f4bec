//! The `flexmech` command line with the built-in joint kinds (see
//! `flexmech::cli` for a binary with more).

use flexmech::model::JointRegistry;

fn main() -> std::process::ExitCode {
    flexmech::cli::main_with(JointRegistry::builtin())
}
