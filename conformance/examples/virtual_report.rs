//! Print the Markdown certificate of the reference model in virtual time.
use hiperface_model::{profiles, Slave};
use hiperface_suite::line::virtual_line::VirtualLine;
use hiperface_suite::report::Reports;
use hiperface_suite::slave::{self, Options};

fn main() {
    let profile = profiles::builtin(&std::env::args().nth(1).unwrap_or_else(|| "SRS50".into())).expect("profile");
    let line = VirtualLine::new(Slave::operational(profile));
    let options = Options::all_allowed();
    let r = slave::run(Box::new(line), profile, &options, |_, _, _| {});
    print!("{}", r.markdown());
}
