//! The `flexmech` command line with the built-in joint kinds (see
//! [`flexmech_studies::cli`] for a binary with more).

use flexmech_studies::model::JointRegistry;

fn main() -> std::process::ExitCode {
    flexmech_studies::cli::main_with(JointRegistry::builtin())
}
