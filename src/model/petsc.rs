//! PETSc's binary format (`MatView`/`MatLoad`, `VecView`/`VecLoad` with a binary viewer): how the
//! distributed path ([`crate::reduction::distributed`], `docs/distributed.md`) hands K, M and
//! right-hand sides to PETSc/SLEPc and reads eigenvectors and solutions back. Pure Rust, no FFI.
//!
//! # The format (PETSc 3.18 with 32-bit `PetscInt`, as Debian builds it)
//! Every number is **big-endian**: integers `i32`, values `f64`.
//!
//! | object | layout |
//! |---|---|
//! | sparse matrix (AIJ) | `1211216`, rows M, columns N, total nnz; M row lengths; nnz column indices (0-based, row by row); nnz values |
//! | dense matrix | `1211216`, M, N, `−1` (`MATRIX_BINARY_FORMAT_DENSE`); M·N values **row by row** |
//! | vector | `1211214`, length n; n values |
//!
//! A file may hold several objects one after the other (`VecView` on one viewer appends):
//! [`read_vecs`] reads vectors until the end of the file. PETSc also writes a `FILE.info`
//! text file of options beside a binary file unless told not to; nothing here needs it.
//!
//! A [`SymCsc`] (both triangles stored) is written as the full AIJ matrix: column j of the
//! symmetric CSC is row j, so the rows come out sorted, as `MatLoad` wants them.
//!
//! Readers check the class id, non-negative sizes, that the sizes fit the file (a dense matrix
//! stored sparsely: the input budget) before anything is allocated, indices in range, and the file's exact length; errors name the file and the
//! part of it ([`Error::Document`]).

use std::io::{BufReader, BufWriter, Read, Write};
use std::path::Path;

use faer::{Mat, MatRef};

use crate::error::Error;
use crate::files;
use crate::linalg::SymCsc;

/// `MAT_FILE_CLASSID`: the first integer of a matrix.
pub const MAT_FILE_CLASSID: i32 = 1_211_216;
/// `VEC_FILE_CLASSID`: the first integer of a vector.
pub const VEC_FILE_CLASSID: i32 = 1_211_214;
/// `MATRIX_BINARY_FORMAT_DENSE`: the nnz field of a dense matrix.
pub const DENSE_FORMAT: i32 = -1;

fn err(file: &Path, at: &str, reason: impl Into<String>) -> Error {
    Error::Document {
        file: file.to_path_buf(),
        path: at.into(),
        reason: format!("PETSc binary: {}", reason.into()),
        source: None,
    }
}

/// A size as PETSc's 32-bit integer, or an error naming `what`.
fn int(path: &Path, what: &str, v: usize) -> Result<i32, Error> {
    i32::try_from(v).map_err(|_| {
        err(
            path,
            what,
            format!("{v} exceeds PETSc's 32-bit PetscInt (Debian's build)"),
        )
    })
}

fn put_i32(w: &mut impl Write, v: i32) -> std::io::Result<()> {
    w.write_all(&v.to_be_bytes())
}

fn put_f64(w: &mut impl Write, v: f64) -> std::io::Result<()> {
    w.write_all(&v.to_be_bytes())
}

/// Writes `a` (symmetric, both triangles stored) as a PETSc AIJ matrix.
pub fn write_sym_aij(path: &Path, a: &SymCsc) -> Result<(), Error> {
    let n = int(path, "header", a.n)?;
    let nnz = int(path, "header", a.values.len())?;
    files::write_atomic_with(path, |tmp| {
        let mut w = BufWriter::new(std::fs::File::create(tmp)?);
        for v in [MAT_FILE_CLASSID, n, n, nnz] {
            put_i32(&mut w, v)?;
        }
        for j in 0..a.n {
            put_i32(&mut w, (a.col_ptr[j + 1] - a.col_ptr[j]) as i32)?;
        }
        for &r in &a.row_idx {
            put_i32(&mut w, r as i32)?;
        }
        for &v in &a.values {
            put_f64(&mut w, v)?;
        }
        w.flush()
    })
}

/// Writes `x` as a PETSc dense matrix (values row by row).
pub fn write_dense(path: &Path, x: MatRef<'_, f64>) -> Result<(), Error> {
    let rows = int(path, "header", x.nrows())?;
    let cols = int(path, "header", x.ncols())?;
    files::write_atomic_with(path, |tmp| {
        let mut w = BufWriter::new(std::fs::File::create(tmp)?);
        for v in [MAT_FILE_CLASSID, rows, cols, DENSE_FORMAT] {
            put_i32(&mut w, v)?;
        }
        for i in 0..x.nrows() {
            for j in 0..x.ncols() {
                put_f64(&mut w, x[(i, j)])?;
            }
        }
        w.flush()
    })
}

/// Writes `v` as one PETSc vector.
pub fn write_vec(path: &Path, v: &[f64]) -> Result<(), Error> {
    let n = int(path, "header", v.len())?;
    files::write_atomic_with(path, |tmp| {
        let mut w = BufWriter::new(std::fs::File::create(tmp)?);
        put_i32(&mut w, VEC_FILE_CLASSID)?;
        put_i32(&mut w, n)?;
        for &x in v {
            put_f64(&mut w, x)?;
        }
        w.flush()
    })
}

/// A bounded reader over one file that knows how many bytes are left.
struct Input<'a> {
    path: &'a Path,
    reader: BufReader<files::BoundedReader>,
    left: u64,
}

impl<'a> Input<'a> {
    fn open(path: &'a Path) -> Result<Self, Error> {
        let reader = BufReader::new(files::BoundedReader::open(path)?);
        let left = std::fs::metadata(path)
            .map_err(|e| Error::Io {
                file: path.to_path_buf(),
                source: e,
            })?
            .len();
        Ok(Input { path, reader, left })
    }

    /// Fails unless `count` items of `size` bytes are left in the file.
    fn need(&self, at: &str, count: usize, size: u64) -> Result<(), Error> {
        let want = (count as u64).saturating_mul(size);
        if want > self.left {
            return Err(err(
                self.path,
                at,
                format!(
                    "needs {want} more bytes, the file has {} left (truncated or wrong sizes)",
                    self.left
                ),
            ));
        }
        Ok(())
    }

    fn bytes<const N: usize>(&mut self, at: &str) -> Result<[u8; N], Error> {
        self.need(at, N, 1)?;
        let mut b = [0u8; N];
        self.reader.read_exact(&mut b).map_err(|e| Error::Io {
            file: self.path.to_path_buf(),
            source: e,
        })?;
        self.left -= N as u64;
        Ok(b)
    }

    fn i32(&mut self, at: &str) -> Result<i32, Error> {
        Ok(i32::from_be_bytes(self.bytes::<4>(at)?))
    }

    fn f64(&mut self, at: &str) -> Result<f64, Error> {
        Ok(f64::from_be_bytes(self.bytes::<8>(at)?))
    }

    /// A non-negative size.
    fn size(&mut self, at: &str) -> Result<usize, Error> {
        let v = self.i32(at)?;
        usize::try_from(v).map_err(|_| err(self.path, at, format!("negative size {v}")))
    }

    fn class(&mut self, want: i32, what: &str) -> Result<(), Error> {
        let id = self.i32("header")?;
        if id != want {
            return Err(err(
                self.path,
                "header",
                format!("class id {id}, expected {want} (a {what})"),
            ));
        }
        Ok(())
    }

    fn finish(&self) -> Result<(), Error> {
        if self.left != 0 {
            return Err(err(
                self.path,
                "end",
                format!("{} bytes after the last object", self.left),
            ));
        }
        Ok(())
    }
}

/// Reads a PETSc dense matrix, in the dense format or in the AIJ format (both are what
/// `MatView` of a dense matrix writes, with and without `PETSC_VIEWER_NATIVE`).
pub fn read_dense(path: &Path) -> Result<Mat<f64>, Error> {
    let mut f = Input::open(path)?;
    f.class(MAT_FILE_CLASSID, "matrix")?;
    let rows = f.size("header: rows")?;
    let cols = f.size("header: columns")?;
    let nz = f.i32("header: nnz")?;
    let x = if nz == DENSE_FORMAT {
        f.need("values", rows.saturating_mul(cols), 8)?;
        let mut x = Mat::<f64>::zeros(rows, cols);
        for i in 0..rows {
            for j in 0..cols {
                x[(i, j)] = f.f64("values")?;
            }
        }
        x
    } else {
        let nnz = usize::try_from(nz)
            .map_err(|_| err(path, "header: nnz", format!("unknown matrix format {nz}")))?;
        // A sparse file may declare a dense size far beyond its bytes: bound the dense copy
        // by the input budget, as if it had been stored densely.
        let bytes = (rows as u64).saturating_mul(cols as u64).saturating_mul(8);
        if bytes > files::input_budget() {
            return Err(err(
                path,
                "header",
                format!(
                    "{rows} × {cols} dense is {bytes} bytes, over the input budget of {} (set {})",
                    files::input_budget(),
                    files::INPUT_BUDGET_VAR
                ),
            ));
        }
        let Aij { ptr, idx, val } = read_aij_body(&mut f, rows, cols, nnz)?;
        let mut x = Mat::<f64>::zeros(rows, cols);
        for i in 0..rows {
            for p in ptr[i]..ptr[i + 1] {
                x[(i, idx[p])] = val[p];
            }
        }
        x
    };
    f.finish()?;
    Ok(x)
}

/// The body of an AIJ matrix in compressed rows.
struct Aij {
    /// Row pointers (rows + 1).
    ptr: Vec<usize>,
    /// Column indices, increasing within each row.
    idx: Vec<usize>,
    /// Values.
    val: Vec<f64>,
}

/// Row lengths, column indices and values of an AIJ matrix after its header: row pointers,
/// column indices (checked in range and increasing within each row) and values.
fn read_aij_body(f: &mut Input<'_>, rows: usize, cols: usize, nnz: usize) -> Result<Aij, Error> {
    f.need("row lengths", rows, 4)?;
    let mut ptr = Vec::with_capacity(rows + 1);
    ptr.push(0usize);
    for i in 0..rows {
        let len = f.size(&format!("row lengths: row {i}"))?;
        ptr.push(ptr[i] + len);
    }
    if ptr[rows] != nnz {
        return Err(err(
            f.path,
            "row lengths",
            format!("row lengths sum to {}, the header says {nnz}", ptr[rows]),
        ));
    }
    f.need("column indices and values", nnz, 12)?;
    let mut idx = Vec::with_capacity(nnz);
    for i in 0..rows {
        for p in ptr[i]..ptr[i + 1] {
            let c = f.size("column indices")?;
            if c >= cols || (p > ptr[i] && c <= idx[p - 1]) {
                return Err(err(
                    f.path,
                    "column indices",
                    format!("row {i}: column {c} out of range (< {cols}) or not increasing"),
                ));
            }
            idx.push(c);
        }
    }
    let mut val = Vec::with_capacity(nnz);
    for _ in 0..nnz {
        val.push(f.f64("values")?);
    }
    Ok(Aij { ptr, idx, val })
}

/// Reads a square AIJ matrix whose pattern and values are symmetric into a [`SymCsc`] (row i
/// of the file is column i). Symmetry of the values is checked exactly: what
/// [`write_sym_aij`] wrote comes back bit for bit.
pub fn read_sym_aij(path: &Path) -> Result<SymCsc, Error> {
    let mut f = Input::open(path)?;
    f.class(MAT_FILE_CLASSID, "matrix")?;
    let rows = f.size("header: rows")?;
    let cols = f.size("header: columns")?;
    let nnz = f.size("header: nnz")?;
    if rows != cols {
        return Err(err(
            path,
            "header",
            format!("{rows} × {cols} is not square"),
        ));
    }
    let Aij {
        ptr: col_ptr,
        idx: row_idx,
        val: values,
    } = read_aij_body(&mut f, rows, cols, nnz)?;
    f.finish()?;
    let a = SymCsc {
        n: rows,
        col_ptr,
        row_idx,
        values,
    };
    for j in 0..a.n {
        for p in a.col_ptr[j]..a.col_ptr[j + 1] {
            let i = a.row_idx[p];
            if a.get(j, i) != a.values[p] {
                return Err(err(
                    path,
                    "values",
                    format!("entry ({i}, {j}) differs from ({j}, {i}): not symmetric"),
                ));
            }
        }
    }
    Ok(a)
}

/// Reads the vectors stored one after another in `path` (at least one).
pub fn read_vecs(path: &Path) -> Result<Vec<Vec<f64>>, Error> {
    let mut f = Input::open(path)?;
    let mut out = Vec::new();
    while out.is_empty() || f.left > 0 {
        let at = format!("vector {}", out.len());
        f.class(VEC_FILE_CLASSID, "vector")?;
        let n = f.size(&at)?;
        f.need(&at, n, 8)?;
        let mut v = Vec::with_capacity(n);
        for _ in 0..n {
            v.push(f.f64(&at)?);
        }
        out.push(v);
    }
    Ok(out)
}
