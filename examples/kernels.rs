//! Rates of the reduced model's matrix–vector kernels against faer's own product on the same
//! matrices (the shapes of `BΦ` and `K̃` of the built-in scenes):
//! `cargo run --release --example kernels`.

use std::hint::black_box;
use std::time::Instant;

use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, Par};
use jointrom::linalg::kernels::{mul_col_major, mul_t_add_row_major};

/// Mean time of `f` over `reps` calls, ns.
fn time_ns(reps: usize, mut f: impl FnMut()) -> f64 {
    let t = Instant::now();
    for _ in 0..reps {
        f();
    }
    t.elapsed().as_nanos() as f64 / reps as f64
}

fn main() {
    println!(
        "shape (m × n): ns and GFlop/s (2mn flops) of y = A x (columns), y += Aᵀ p (rows), faer"
    );
    for (m, n) in [(156usize, 28usize), (156, 68), (600, 54), (68, 68)] {
        let a: Vec<f64> = (0..m * n).map(|k| (k % 13) as f64 * 0.1 - 0.5).collect();
        let x: Vec<f64> = (0..n).map(|k| k as f64 + 1.0).collect();
        let p: Vec<f64> = (0..m).map(|k| k as f64 + 1.0).collect();
        let (mut y, mut z) = (vec![0.0; m], vec![0.0; n]);
        let reps = 100_000;
        let t_mul = time_ns(reps, || {
            mul_col_major(black_box(&a), black_box(&x), &mut y);
            black_box(&y);
        });
        let t_mul_t = time_ns(reps, || {
            mul_t_add_row_major(black_box(&a), black_box(&p), &mut z);
            black_box(&z);
        });
        let fa = Mat::<f64>::from_fn(m, n, |i, j| a[j * m + i]);
        let fx = Mat::<f64>::from_fn(n, 1, |i, _| x[i]);
        let mut fy = Mat::<f64>::zeros(m, 1);
        let t_faer = time_ns(reps, || {
            matmul(
                fy.as_mut(),
                Accum::Replace,
                black_box(&fa).as_ref(),
                fx.as_ref(),
                1.0,
                Par::Seq,
            );
            black_box(&fy);
        });
        let fl = 2.0 * (m * n) as f64;
        println!(
            "{m:4} × {n:3}: {t_mul:6.0} ns {:5.1} | {t_mul_t:6.0} ns {:5.1} | faer {t_faer:6.0} ns {:5.1}",
            fl / t_mul,
            fl / t_mul_t,
            fl / t_faer
        );
    }
}
