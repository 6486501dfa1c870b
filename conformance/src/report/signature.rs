//! Signed certificates: who made a report, and that nothing in it changed since.
//!
//! `certify … --sign KEY` writes `report.sig` beside the reports: the SHA-256 of each
//! file the run wrote (`report.json` holds the verdicts and the record of the wire),
//! the signer's public key, and an Ed25519 signature over both. `decode report.json
//! --verify PUBKEY` checks it before anything else: the key is the one given, the
//! signature holds, and the report's bytes (the very bytes then decoded) and every
//! other signed file present hash as signed. One byte changed anywhere is caught.
//!
//! Keys are PKCS#8 / SPKI PEM files, as OpenSSL writes them (`openssl genpkey
//! -algorithm ed25519`, `openssl pkey -pubout`), or made by `hiperface keygen`.

use crate::command::CommandError;
use ed25519_dalek::pkcs8::{DecodePrivateKey, DecodePublicKey, EncodePrivateKey, EncodePublicKey};
use ed25519_dalek::{Signer as _, SigningKey, VerifyingKey};
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The signature's file, beside the reports.
pub const FILE: &str = "report.sig";

/// What a signature file says it is.
pub const FORMAT: &str = "hiperface-signature-1";

/// A key or signature file is far smaller: larger ones are not read.
const MAX_KEY_BYTES: u64 = 64 << 10;

/// The signature file.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SignatureFile {
    pub format: String,
    pub algorithm: String,
    /// The signer's public key, 32 bytes in hex.
    pub public_key: String,
    /// Each signed file's name and its SHA-256, hex.
    pub files: BTreeMap<String, String>,
    /// Ed25519 over [`message`], 64 bytes in hex.
    pub signature: String,
}

/// The bytes signed: the format, the key and each file's digest, a line each, in the
/// files' name order.
fn message(public_key: &str, files: &BTreeMap<String, String>) -> Vec<u8> {
    let mut m = format!("{FORMAT}\ned25519 {public_key}\n");
    for (name, digest) in files {
        m.push_str(&format!("sha256 {digest} {name}\n"));
    }
    m.into_bytes()
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

fn unhex<const N: usize>(s: &str) -> Option<[u8; N]> {
    if s.len() != 2 * N || !s.is_ascii() {
        return None;
    }
    let mut out = [0u8; N];
    for (i, o) in out.iter_mut().enumerate() {
        *o = u8::from_str_radix(s.get(2 * i..2 * i + 2)?, 16).ok()?;
    }
    Some(out)
}

/// The SHA-256 of `bytes`, hex.
pub fn digest(bytes: &[u8]) -> String {
    hex(&Sha256::digest(bytes))
}

fn read_small(path: &Path, what: &str) -> Result<String, CommandError> {
    use std::io::Read;
    let file = std::fs::File::open(path).map_err(CommandError::file(path))?;
    let mut text = String::new();
    file.take(MAX_KEY_BYTES + 1).read_to_string(&mut text).map_err(|e| CommandError::Input {
        name: path.display().to_string(),
        why: format!("cannot be read as {what}: {e}"),
    })?;
    if text.len() as u64 > MAX_KEY_BYTES {
        return Err(CommandError::Input {
            name: path.display().to_string(),
            why: format!("larger than {} KiB: not {what}", MAX_KEY_BYTES >> 10),
        });
    }
    Ok(text)
}

/// A signing key, read before a run (a key that does not load stops the run before it
/// starts, exit 2).
pub struct Signer {
    key: SigningKey,
}

impl Signer {
    /// The private key at `path` (PKCS#8 PEM, Ed25519).
    pub fn load(path: &Path) -> Result<Signer, CommandError> {
        let pem = read_small(path, "a private key")?;
        let key = SigningKey::from_pkcs8_pem(&pem).map_err(|e| CommandError::Input {
            name: path.display().to_string(),
            why: format!(
                "not an Ed25519 private key in PKCS#8 PEM ({e}); make one with `hiperface keygen --out FILE` or \
                 `openssl genpkey -algorithm ed25519`"
            ),
        })?;
        Ok(Signer { key })
    }

    /// Sign the files `names` of `dir` as they are now: write `dir/report.sig`.
    pub fn sign(&self, dir: &Path, names: &[&str]) -> std::io::Result<()> {
        let mut files = BTreeMap::new();
        for name in names {
            files.insert(name.to_string(), digest(&std::fs::read(dir.join(name))?));
        }
        let public_key = hex(self.key.verifying_key().as_bytes());
        let signature = hex(&self.key.sign(&message(&public_key, &files)).to_bytes());
        let file = SignatureFile { format: FORMAT.into(), algorithm: "ed25519".into(), public_key, files, signature };
        let text = serde_json::to_string_pretty(&file).map_err(std::io::Error::other)?;
        std::fs::write(dir.join(FILE), text + "\n")
    }
}

/// Make a key pair: the private key at `out` (mode 0600, never over an existing file)
/// and the public key at `out.pub`. Returns the public key's path.
pub fn generate(out: &Path) -> Result<PathBuf, CommandError> {
    use std::io::Write;
    use std::os::unix::fs::OpenOptionsExt;
    let public = PathBuf::from(format!("{}.pub", out.display()));
    for p in [out, public.as_path()] {
        if p.symlink_metadata().is_ok() {
            return Err(CommandError::Usage(format!(
                "{}: exists; a key is never overwritten (move it away or choose another name)",
                p.display()
            )));
        }
    }
    let key = SigningKey::generate(&mut rand_core::OsRng);
    let encode = |e: ed25519_dalek::pkcs8::Error| CommandError::Usage(format!("cannot encode the key: {e}"));
    let private = key.to_pkcs8_pem(Default::default()).map_err(encode)?;
    let public_pem = key
        .verifying_key()
        .to_public_key_pem(Default::default())
        .map_err(|e| CommandError::Usage(format!("cannot encode the public key: {e}")))?;
    let mut f = std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .mode(0o600)
        .open(out)
        .map_err(CommandError::file(out))?;
    f.write_all(private.as_bytes()).map_err(CommandError::file(out))?;
    std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&public)
        .and_then(|mut f| f.write_all(public_pem.as_bytes()))
        .map_err(CommandError::file(&public))?;
    Ok(public)
}

/// What a verification found.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Verified {
    /// The signed files whose bytes were checked.
    pub checked: Vec<String>,
    /// Signed files not beside the report (not checked: a report passed on alone).
    pub absent: Vec<String>,
}

/// Why a report's signature does not hold; each is the report being no evidence of
/// the signer's run (exit 5).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum Unverified {
    #[error("no signature: {0} is not there or cannot be read")]
    Missing(String),
    #[error("the signature file {0} cannot be read: {1}")]
    Unreadable(String, String),
    #[error("signed with another key ({found}), not the one given ({given})")]
    OtherKey { found: String, given: String },
    #[error("the signature does not hold: the signature file was changed")]
    BadSignature,
    #[error("{0} was not signed")]
    NotSigned(String),
    #[error("{0} changed since it was signed (its SHA-256 is not the signed one)")]
    Changed(String),
}

/// The public key at `path` (SPKI PEM, Ed25519).
pub fn load_public(path: &Path) -> Result<VerifyingKey, CommandError> {
    let pem = read_small(path, "a public key")?;
    VerifyingKey::from_public_key_pem(&pem).map_err(|e| CommandError::Input {
        name: path.display().to_string(),
        why: format!(
            "not an Ed25519 public key in PEM ({e}); `hiperface keygen` writes it beside the private key as FILE.pub, \
             `openssl pkey -pubout` makes it from one"
        ),
    })
}

/// Verify the report `report_name` of `dir`, whose bytes are `report` (the bytes the
/// caller then decodes), against `key`: the signature file beside it, the key, the
/// signature, the report's digest, and the digest of every other signed file present.
pub fn verify(key: &VerifyingKey, dir: &Path, report_name: &str, report: &[u8]) -> Result<Verified, Unverified> {
    let sig_path = dir.join(FILE);
    let shown = sig_path.display().to_string();
    let text = read_small(&sig_path, "a signature").map_err(|_| Unverified::Missing(shown.clone()))?;
    let file: SignatureFile =
        serde_json::from_str(&text).map_err(|e| Unverified::Unreadable(shown.clone(), e.to_string()))?;
    if file.format != FORMAT || file.algorithm != "ed25519" {
        return Err(Unverified::Unreadable(
            shown,
            format!("format {} {}, not {FORMAT} ed25519", file.format, file.algorithm),
        ));
    }
    let given = hex(key.as_bytes());
    if file.public_key != given {
        return Err(Unverified::OtherKey { found: file.public_key, given });
    }
    let signature = unhex::<64>(&file.signature)
        .ok_or_else(|| Unverified::Unreadable(shown.clone(), "the signature is not 64 bytes of hex".into()))?;
    key.verify_strict(&message(&file.public_key, &file.files), &ed25519_dalek::Signature::from_bytes(&signature))
        .map_err(|_| Unverified::BadSignature)?;
    let signed = file.files.get(report_name).ok_or_else(|| Unverified::NotSigned(report_name.to_string()))?;
    if *signed != digest(report) {
        return Err(Unverified::Changed(report_name.to_string()));
    }
    let mut verified = Verified { checked: vec![report_name.to_string()], absent: Vec::new() };
    for (name, signed) in file.files.iter().filter(|(n, _)| *n != report_name) {
        // Only plain names are signed; a name with a path in it is no file of the run.
        if name.contains('/') || name.starts_with('.') {
            return Err(Unverified::NotSigned(name.clone()));
        }
        match std::fs::read(dir.join(name)) {
            Ok(bytes) if digest(&bytes) == *signed => verified.checked.push(name.clone()),
            Ok(_) => return Err(Unverified::Changed(name.clone())),
            Err(_) => verified.absent.push(name.clone()),
        }
    }
    Ok(verified)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn signed_dir() -> (tempfile::TempDir, VerifyingKey) {
        let tmp = tempfile::tempdir().unwrap();
        let key = tmp.path().join("lab.pem");
        let public = generate(&key).unwrap();
        let dir = tmp.path().join("run");
        std::fs::create_dir(&dir).unwrap();
        std::fs::write(dir.join("report.json"), "{\"outcome\":\"PASSED\"}\n").unwrap();
        std::fs::write(dir.join("certificate.md"), "# PASSED\n").unwrap();
        Signer::load(&key).unwrap().sign(&dir, &["report.json", "certificate.md"]).unwrap();
        let public = load_public(&public).unwrap();
        (tmp, public)
    }

    #[test]
    fn a_signed_report_verifies_and_any_byte_changed_is_caught() {
        let (tmp, key) = signed_dir();
        let dir = tmp.path().join("run");
        let report = std::fs::read(dir.join("report.json")).unwrap();
        let ok = verify(&key, &dir, "report.json", &report).unwrap();
        assert_eq!(ok.checked, ["report.json", "certificate.md"]);
        // Every byte of the report, flipped one at a time.
        for i in 0..report.len() {
            let mut changed = report.clone();
            changed[i] ^= 0x01;
            assert_eq!(verify(&key, &dir, "report.json", &changed), Err(Unverified::Changed("report.json".into())));
        }
        // The certificate beside it.
        std::fs::write(dir.join("certificate.md"), "# PASSED!\n").unwrap();
        assert_eq!(verify(&key, &dir, "report.json", &report), Err(Unverified::Changed("certificate.md".into())));
        // Absent: not checked, said.
        std::fs::remove_file(dir.join("certificate.md")).unwrap();
        assert_eq!(verify(&key, &dir, "report.json", &report).unwrap().absent, ["certificate.md"]);
    }

    #[test]
    fn the_signature_file_itself_cannot_be_edited() {
        let (tmp, key) = signed_dir();
        let dir = tmp.path().join("run");
        let report = std::fs::read(dir.join("report.json")).unwrap();
        let sig = std::fs::read_to_string(dir.join(FILE)).unwrap();
        // A new digest for an edited report: the signature no longer holds.
        let mut file: SignatureFile = serde_json::from_str(&sig).unwrap();
        file.files.insert("report.json".into(), digest(b"{\"outcome\":\"FAILED\"}\n"));
        std::fs::write(dir.join(FILE), serde_json::to_string(&file).unwrap()).unwrap();
        assert_eq!(verify(&key, &dir, "report.json", b"{\"outcome\":\"FAILED\"}\n"), Err(Unverified::BadSignature));
        // Every character of the signature file, changed one at a time: never verifies.
        let bytes = sig.as_bytes();
        for i in 0..bytes.len() {
            let mut changed = bytes.to_vec();
            changed[i] = if changed[i] == b'0' { b'1' } else { b'0' };
            std::fs::write(dir.join(FILE), &changed).unwrap();
            assert!(verify(&key, &dir, "report.json", &report).is_err(), "byte {i} of the signature file");
        }
        // Another lab's key.
        let other = tmp.path().join("other.pem");
        let other_public = load_public(&generate(&other).unwrap()).unwrap();
        std::fs::write(dir.join(FILE), sig).unwrap();
        assert!(matches!(verify(&other_public, &dir, "report.json", &report), Err(Unverified::OtherKey { .. })));
        std::fs::remove_file(dir.join(FILE)).unwrap();
        assert!(matches!(verify(&key, &dir, "report.json", &report), Err(Unverified::Missing(_))));
    }

    #[test]
    fn a_key_is_never_overwritten_and_stays_private() {
        use std::os::unix::fs::PermissionsExt;
        let tmp = tempfile::tempdir().unwrap();
        let key = tmp.path().join("lab.pem");
        generate(&key).unwrap();
        let mode = std::fs::metadata(&key).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode, 0o600);
        let before = std::fs::read(&key).unwrap();
        assert!(generate(&key).is_err());
        assert_eq!(std::fs::read(&key).unwrap(), before);
        // A public key is no private key, and the reverse.
        assert!(Signer::load(&tmp.path().join("lab.pem.pub")).is_err());
        assert!(load_public(&key).is_err());
    }
}
