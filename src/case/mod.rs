//! Case files: serde schema (units mm, N, t, s) and validation. (Being written.)
