//! A seeded, structure-aware mutator: byte edits, number swaps with extreme values, JSON
//! subtree edits and line edits (MatrixMarket), one to three per input.

use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use serde_json::Value;

/// Replacement numbers and tokens: zero, signs, extremes, non-numbers, huge integers.
const TOKENS: &[&str] = &[
    "0",
    "-1",
    "1",
    "-0.5",
    "1e308",
    "-1e308",
    "1e-320",
    "1e400",
    "NaN",
    "inf",
    "18446744073709551615",
    "18446744073709551616",
    "9223372036854775807",
    "1000000000000",
    "2000000",
    "\"x\"",
    "null",
    "[]",
    "{}",
    "true",
];

pub struct Mutator {
    rng: StdRng,
}

impl Mutator {
    pub fn new(seed: u64) -> Self {
        Mutator {
            rng: StdRng::seed_from_u64(seed),
        }
    }

    /// One mutant of `seed`.
    pub fn mutate(&mut self, seed: &[u8]) -> Vec<u8> {
        let mut v = seed.to_vec();
        let rounds = self.rng.random_range(1..=3);
        for _ in 0..rounds {
            v = match self.rng.random_range(0..10) {
                0 => self.flip(v),
                1 => self.cut(v),
                2 => self.duplicate(v),
                3..=5 => self.number(v),
                6 | 7 => self.json(v),
                _ => self.lines(v),
            };
        }
        v
    }

    fn pos(&mut self, len: usize) -> usize {
        if len == 0 {
            0
        } else {
            self.rng.random_range(0..len)
        }
    }

    fn flip(&mut self, mut v: Vec<u8>) -> Vec<u8> {
        if !v.is_empty() {
            let i = self.pos(v.len());
            v[i] ^= 1 << self.rng.random_range(0..8);
        }
        v
    }

    fn cut(&mut self, mut v: Vec<u8>) -> Vec<u8> {
        let a = self.pos(v.len());
        let b = (a + self.rng.random_range(0..64)).min(v.len());
        if self.rng.random_bool(0.2) {
            v.truncate(a);
        } else {
            v.drain(a..b);
        }
        v
    }

    fn duplicate(&mut self, mut v: Vec<u8>) -> Vec<u8> {
        let a = self.pos(v.len());
        let b = (a + self.rng.random_range(0..64)).min(v.len());
        let piece = v[a..b].to_vec();
        let at = self.pos(v.len());
        v.splice(at..at, piece);
        v
    }

    /// Replaces one run of digits (with its sign, point and exponent) by a token.
    fn number(&mut self, v: Vec<u8>) -> Vec<u8> {
        let starts: Vec<usize> = (0..v.len())
            .filter(|&i| v[i].is_ascii_digit() && (i == 0 || !is_num(v[i - 1])))
            .collect();
        if starts.is_empty() {
            return v;
        }
        let s = starts[self.pos(starts.len())];
        let s = if s > 0 && v[s - 1] == b'-' { s - 1 } else { s };
        let mut e = s + 1;
        while e < v.len() && is_num(v[e]) {
            e += 1;
        }
        let tok = TOKENS[self.pos(TOKENS.len())].as_bytes();
        let mut out = v[..s].to_vec();
        out.extend_from_slice(tok);
        out.extend_from_slice(&v[e..]);
        out
    }

    /// Edits a random subtree of a JSON document: removes it, duplicates an array element, or
    /// replaces it with a token.
    fn json(&mut self, v: Vec<u8>) -> Vec<u8> {
        let Ok(mut doc) = serde_json::from_slice::<Value>(&v) else {
            return self.flip(v);
        };
        let depth = self.rng.random_range(0..5);
        let action = self.rng.random_range(0..3);
        let tok = TOKENS[self.pos(TOKENS.len())];
        let replacement: Value = serde_json::from_str(tok).unwrap_or(Value::Null);
        let mut node = &mut doc;
        for _ in 0..depth {
            let len = match node {
                Value::Object(m) => m.len(),
                Value::Array(a) => a.len(),
                _ => 0,
            };
            if len == 0 {
                break;
            }
            let k = self.pos(len);
            node = match node {
                Value::Object(m) => {
                    let key = m.keys().nth(k).unwrap().clone();
                    if action == 0 && self.rng.random_bool(0.3) {
                        m.remove(&key);
                        return serde_json::to_vec(&doc).unwrap();
                    }
                    m.get_mut(&key).unwrap()
                }
                Value::Array(a) => {
                    if action == 1 && self.rng.random_bool(0.3) {
                        let e = a[k].clone();
                        a.push(e);
                        return serde_json::to_vec(&doc).unwrap();
                    }
                    &mut a[k]
                }
                _ => unreachable!(),
            };
        }
        *node = replacement;
        serde_json::to_vec(&doc).unwrap()
    }

    /// Deletes, duplicates or swaps whole lines.
    fn lines(&mut self, v: Vec<u8>) -> Vec<u8> {
        let text = String::from_utf8_lossy(&v);
        let mut lines: Vec<&str> = text.lines().collect();
        if lines.is_empty() {
            return v;
        }
        let i = self.pos(lines.len());
        match self.rng.random_range(0..3) {
            0 => {
                lines.remove(i);
            }
            1 => lines.insert(i, lines[i]),
            _ => {
                let j = self.pos(lines.len());
                lines.swap(i, j);
            }
        }
        let mut out = lines.join("\n");
        out.push('\n');
        out.into_bytes()
    }
}

fn is_num(b: u8) -> bool {
    b.is_ascii_digit() || matches!(b, b'.' | b'e' | b'E' | b'+' | b'-')
}
