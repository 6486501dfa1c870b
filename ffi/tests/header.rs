//! The committed C header is what cbindgen makes of the crate today: a change of the
//! API without its header fails here. `HIPERFACE_BLESS=1 cargo test -p hiperface-ffi
//! --test header` writes it.

use std::path::Path;

#[test]
fn the_header_is_current() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let config = cbindgen::Config::from_file(dir.join("cbindgen.toml")).expect("ffi/cbindgen.toml");
    let mut generated = Vec::new();
    cbindgen::Builder::new()
        .with_crate(dir)
        .with_config(config)
        .generate()
        .expect("cbindgen generates the header")
        .write(&mut generated);
    let path = dir.join("include/hiperface.h");
    if std::env::var_os("HIPERFACE_BLESS").is_some() {
        std::fs::write(&path, &generated).expect("write the header");
    }
    let committed = std::fs::read(&path).unwrap_or_default();
    assert!(
        committed == generated,
        "ffi/include/hiperface.h is not current: run `HIPERFACE_BLESS=1 cargo test -p hiperface-ffi --test header`"
    );
}
