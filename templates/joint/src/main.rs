//! flexmech's command line with one more joint kind: `run`, `check`,
//! `study`, `plot`, `export`, `animate` read model files that name
//! `type = "my_joint"`.

mod joint;

use flexmech::App;

fn main() -> std::process::ExitCode {
    App::new().joint::<joint::MyJoint>().main()
}
