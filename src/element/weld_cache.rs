//! The re-meshed weld neighbourhoods' condensations on disk, so that a model is built from them
//! once per machine rather than once per command.
//!
//! A condensation depends only on its key ([`super::weld`]'s `condensation_key`: the
//! neighbourhood's geometry relative to the weld centre, the mesh rule's sizes and the material
//! bits). An entry is the file `DIR/<sha256(key)>.cond` holding
//!
//! ```text
//! "JRCOND1\n" | key length, key (i64 LE) | K: rows, cols, values (f64 LE, column-major)
//!             | M: rows, cols, values | SHA-256 of everything before it
//! ```
//!
//! An entry is used only if its magic, its full key (not just the hash in its name), its sizes
//! and its checksum match — a stale, truncated or corrupted file is ignored and rewritten, never
//! trusted. Entries are written to a temporary file and renamed into place, so concurrent
//! commands never read half an entry. The values are stored bit for bit: a model built from the
//! cache is identical to one built without it.
//!
//! `DIR` is `$JOINTROM_CACHE_DIR`, else `$XDG_CACHE_HOME/jointrom`, else `$HOME/.cache/jointrom`;
//! `JOINTROM_CACHE_DIR=off` (or empty) turns the disk cache off. A cache that cannot be read or
//! written is skipped silently: it only saves time.

use std::io::Write;
use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};

use faer::Mat;
use sha2::{Digest, Sha256};

const MAGIC: &[u8; 8] = b"JRCOND1\n";

/// The largest entry read or written, bytes (a neighbourhood's matrices are far smaller).
const MAX_ENTRY_BYTES: usize = 256 << 20;

/// The cache folder, or `None` when the disk cache is off or no folder is known.
fn dir() -> Option<PathBuf> {
    match std::env::var_os("JOINTROM_CACHE_DIR") {
        Some(v) if v.is_empty() || v == "off" => None,
        Some(v) => Some(PathBuf::from(v)),
        None => std::env::var_os("XDG_CACHE_HOME")
            .filter(|v| !v.is_empty())
            .map(|v| PathBuf::from(v).join("jointrom"))
            .or_else(|| {
                std::env::var_os("HOME")
                    .filter(|v| !v.is_empty())
                    .map(|h| PathBuf::from(h).join(".cache").join("jointrom"))
            }),
    }
}

fn entry_path(key: &[i64]) -> Option<PathBuf> {
    let mut h = Sha256::new();
    for k in key {
        h.update(k.to_le_bytes());
    }
    let name: String = h.finalize().iter().map(|b| format!("{b:02x}")).collect();
    Some(dir()?.join(format!("{name}.cond")))
}

fn encode(key: &[i64], k: &Mat<f64>, m: &Mat<f64>) -> Vec<u8> {
    let mut out = Vec::with_capacity(64 + 8 * (key.len() + k.nrows() * k.ncols() * 2));
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&(key.len() as u64).to_le_bytes());
    for v in key {
        out.extend_from_slice(&v.to_le_bytes());
    }
    for a in [k, m] {
        out.extend_from_slice(&(a.nrows() as u64).to_le_bytes());
        out.extend_from_slice(&(a.ncols() as u64).to_le_bytes());
        for j in 0..a.ncols() {
            for i in 0..a.nrows() {
                out.extend_from_slice(&a[(i, j)].to_bits().to_le_bytes());
            }
        }
    }
    let sum = Sha256::digest(&out);
    out.extend_from_slice(&sum);
    out
}

/// A reader of the entry's fields; every read is bounds-checked.
struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl Reader<'_> {
    fn u64(&mut self) -> Option<u64> {
        let b = self.bytes.get(self.at..self.at + 8)?;
        self.at += 8;
        Some(u64::from_le_bytes(b.try_into().ok()?))
    }

    fn matrix(&mut self) -> Option<Mat<f64>> {
        let (r, c) = (self.u64()? as usize, self.u64()? as usize);
        let n = r.checked_mul(c)?;
        if n.checked_mul(8)? > self.bytes.len().saturating_sub(self.at) {
            return None;
        }
        let mut values = Vec::with_capacity(n);
        for _ in 0..n {
            values.push(f64::from_bits(self.u64()?));
        }
        Some(Mat::from_fn(r, c, |i, j| values[j * r + i]))
    }
}

fn decode(bytes: &[u8], key: &[i64]) -> Option<(Mat<f64>, Mat<f64>)> {
    let body_len = bytes.len().checked_sub(32)?;
    let (body, sum) = bytes.split_at(body_len);
    if body.get(..8)? != MAGIC || Sha256::digest(body).as_slice() != sum {
        return None;
    }
    let mut r = Reader { bytes: body, at: 8 };
    let len = r.u64()? as usize;
    if len != key.len() {
        return None;
    }
    for &k in key {
        if r.u64()? as i64 != k {
            return None;
        }
    }
    let k = r.matrix()?;
    let m = r.matrix()?;
    (r.at == body.len()
        && k.nrows() == k.ncols()
        && m.nrows() == k.nrows()
        && m.ncols() == k.ncols())
    .then_some((k, m))
}

/// The condensation stored under `key`, if the disk cache has a sound entry for it.
pub(super) fn load(key: &[i64]) -> Option<(Mat<f64>, Mat<f64>)> {
    let path = entry_path(key)?;
    let meta = std::fs::metadata(&path).ok()?;
    if !meta.is_file() || meta.len() as usize > MAX_ENTRY_BYTES {
        return None;
    }
    decode(&std::fs::read(&path).ok()?, key)
}

/// Stores a condensation under `key` (best effort: failures are ignored).
pub(super) fn store(key: &[i64], k: &Mat<f64>, m: &Mat<f64>) {
    static SEQ: AtomicUsize = AtomicUsize::new(0);
    let Some(path) = entry_path(key) else { return };
    let bytes = encode(key, k, m);
    if bytes.len() > MAX_ENTRY_BYTES {
        return;
    }
    let Some(dir) = path.parent() else { return };
    if std::fs::create_dir_all(dir).is_err() {
        return;
    }
    let tmp = dir.join(format!(
        ".{}.{}.{}.tmp",
        path.file_name()
            .map(|n| n.to_string_lossy())
            .unwrap_or_default(),
        std::process::id(),
        SEQ.fetch_add(1, Ordering::Relaxed)
    ));
    let written = std::fs::File::create(&tmp).and_then(|mut f| f.write_all(&bytes));
    if written.is_err() || std::fs::rename(&tmp, &path).is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn entries_round_trip_bit_for_bit_and_damage_is_refused() {
        let k = Mat::from_fn(3, 3, |i, j| (i * 3 + j) as f64 * 0.1 + 1e-300);
        let m = Mat::from_fn(3, 3, |i, j| if i == j { -0.0 } else { 1.0 / 3.0 });
        let key = vec![1, -2, 3];
        let bytes = encode(&key, &k, &m);
        let (k2, m2) = decode(&bytes, &key).expect("a sound entry decodes");
        for j in 0..3 {
            for i in 0..3 {
                assert_eq!(k[(i, j)].to_bits(), k2[(i, j)].to_bits());
                assert_eq!(m[(i, j)].to_bits(), m2[(i, j)].to_bits());
            }
        }
        assert!(decode(&bytes, &[1, -2, 4]).is_none(), "another key");
        for cut in [0, 7, 40, bytes.len() - 1] {
            assert!(decode(&bytes[..cut], &key).is_none(), "truncated at {cut}");
        }
        let mut flipped = bytes.clone();
        flipped[60] ^= 1;
        assert!(decode(&flipped, &key).is_none(), "a flipped bit");
    }
}
