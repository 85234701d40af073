//! PETSc's binary format (`jointrom::model::petsc`): the friction bar's K and a dense block
//! round-trip bit for bit; the bytes are PETSc's big-endian layout (checked against the header
//! by hand); truncated, foreign and non-symmetric files are rejected naming the file.

use faer::Mat;
use jointrom::model::petsc;

use crate::common;

fn dir(name: &str) -> std::path::PathBuf {
    common::tmp_dir(&format!("petsc_{name}"))
}

#[test]
fn sym_aij_round_trips_bit_for_bit() {
    let model = common::model("friction_bar");
    let d = dir("aij");
    let path = d.join("K.petsc");
    petsc::write_sym_aij(&path, &model.stiffness).unwrap();
    let back = petsc::read_sym_aij(&path).unwrap();
    assert_eq!(back.n, model.stiffness.n);
    assert_eq!(back.col_ptr, model.stiffness.col_ptr);
    assert_eq!(back.row_idx, model.stiffness.row_idx);
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&back.values), bits(&model.stiffness.values));
    // The header: class id, rows, columns, nnz, big-endian 32-bit.
    let bytes = std::fs::read(&path).unwrap();
    let int = |i: usize| i32::from_be_bytes(bytes[4 * i..4 * i + 4].try_into().unwrap());
    let (n, nnz) = (model.stiffness.n, model.stiffness.values.len());
    assert_eq!(
        [int(0), int(1), int(2), int(3)],
        [1_211_216, n as i32, n as i32, nnz as i32]
    );
    assert_eq!(bytes.len(), 16 + 4 * n + 12 * nnz);
}

#[test]
fn dense_and_vectors_round_trip() {
    let d = dir("dense");
    let x = Mat::from_fn(7, 3, |i, j| {
        (i as f64 + 0.1) * (j as f64 - 1.3).powi(3) / 3.0
    });
    let path = d.join("X.petsc");
    petsc::write_dense(&path, x.as_ref()).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    assert_eq!(bytes.len(), 16 + 8 * 21);
    // Row by row: the second value is X[0, 1].
    let v1 = f64::from_be_bytes(bytes[24..32].try_into().unwrap());
    assert_eq!(v1.to_bits(), x[(0, 1)].to_bits());
    let back = petsc::read_dense(&path).unwrap();
    assert_eq!(back.shape(), (7, 3));
    for i in 0..7 {
        for j in 0..3 {
            assert_eq!(back[(i, j)].to_bits(), x[(i, j)].to_bits());
        }
    }
    let vpath = d.join("v.petsc");
    petsc::write_vec(&vpath, &[1.0, -2.5, 1e-300]).unwrap();
    assert_eq!(
        petsc::read_vecs(&vpath).unwrap(),
        vec![vec![1.0, -2.5, 1e-300]]
    );
    // Two vectors one after the other (what VecView appends).
    let mut two = std::fs::read(&vpath).unwrap();
    two.extend_from_slice(&two.clone());
    std::fs::write(&vpath, &two).unwrap();
    assert_eq!(petsc::read_vecs(&vpath).unwrap().len(), 2);
}

#[test]
fn damaged_files_are_rejected_naming_the_file() {
    let model = common::model("friction_bar");
    let d = dir("damaged");
    let path = d.join("K.petsc");
    petsc::write_sym_aij(&path, &model.stiffness).unwrap();
    let good = std::fs::read(&path).unwrap();
    let expect = |bytes: &[u8], what: &str| {
        std::fs::write(&path, bytes).unwrap();
        let e = petsc::read_sym_aij(&path).unwrap_err().to_string();
        assert!(e.contains("K.petsc") && e.contains(what), "{e}");
    };
    expect(&good[..good.len() - 3], "needs");
    expect(&good[..10], "needs");
    let mut foreign = good.clone();
    foreign[3] ^= 1;
    expect(&foreign, "class id");
    let mut extra = good.clone();
    extra.push(0);
    expect(&extra, "after the last object");
    // An off-diagonal value changed on one side only.
    let n = model.stiffness.n;
    let nnz = model.stiffness.values.len();
    let off = (0..model.stiffness.col_ptr[1])
        .find(|&p| model.stiffness.row_idx[p] != 0)
        .unwrap();
    let mut asym = good.clone();
    let at = 16 + 4 * n + 4 * nnz + 8 * off;
    asym[at + 7] ^= 1;
    expect(&asym, "not symmetric");
    // A huge declared size fails before any allocation.
    let mut huge = good;
    huge[4..8].copy_from_slice(&i32::MAX.to_be_bytes());
    huge[8..12].copy_from_slice(&i32::MAX.to_be_bytes());
    expect(&huge, "needs");
    // A dense reader on a vector file, a vector reader on a matrix.
    let v = d.join("v.petsc");
    petsc::write_vec(&v, &[1.0]).unwrap();
    assert!(petsc::read_dense(&v)
        .unwrap_err()
        .to_string()
        .contains("class id"));
    assert!(petsc::read_vecs(&path)
        .unwrap_err()
        .to_string()
        .contains("class id"));
}
