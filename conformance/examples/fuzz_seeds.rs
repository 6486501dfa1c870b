//! Write the fuzz seed corpus from the golden vectors: every request of every vector
//! into `fuzz/corpus/{request,response,datalink,slave,observer}/`.
//! Run: `cargo run -p hiperface-conformance --example fuzz_seeds`.

use hiperface_suite::vectors;
use std::path::Path;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut n = 0;
    for path in vectors::files(&root.join("vectors"))? {
        for v in vectors::load(&path)?.vectors {
            for (i, s) in v.steps.iter().enumerate() {
                let bytes = vectors::parse_hex(&s.request)?;
                for target in ["request", "response", "datalink", "slave", "observer"] {
                    let dir = root.join("fuzz/corpus").join(target);
                    std::fs::create_dir_all(&dir)?;
                    std::fs::write(dir.join(format!("{}-{i}", v.id)), &bytes)?;
                }
                n += 1;
            }
        }
    }
    println!("{n} seeds per target");
    Ok(())
}
