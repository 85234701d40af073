//! Build script: bindings for the parts of SUNDIALS 6.4 that `sundials-sys` 0.6 does not expose,
//! and jointrom's small C shim.
//!
//! 1. Finds the SUNDIALS headers: `$SUNDIALS_INCLUDE_DIR` if set (the variable `sundials-sys`
//!    reads too), else `/usr/include` or `/usr/local/include`; fails with the Debian packages to
//!    install if none holds `sundials/sundials_config.h`, or if the version found is not 6.x.
//! 2. Runs bindgen on `vendor-headers/jointrom_sundials.h`, keeping only the items declared in
//!    that header and in the SUNDIALS headers it adds (`sundials_version.h`, `cvode_diag.h`,
//!    `cvode_bandpre.h`, ARKODE's `arkode.h`, `arkode_ls.h`, `arkode_arkstep.h` and its Butcher
//!    tables) plus the version macros; the types they use (`N_Vector`,
//!    `sunindextype`, ...) are not generated but taken from `sundials-sys`, so they stay
//!    compatible. Output: `$OUT_DIR/jointrom_sundials.rs`, included by `src/sundials/ffi.rs`.
//! 3. Compiles `vendor-headers/jointrom_sundials.c` with `cc` into a static library. Its
//!    undefined SUNDIALS symbols are resolved by the shared libraries `sundials-sys` links.

use std::env;
use std::path::{Path, PathBuf};

/// What to install when something is missing (Debian bookworm; `.ci/setup` does it).
const APT_HINT: &str = "on Debian/Ubuntu run `.ci/setup --no-run` as root, or \
     `apt-get install --no-install-recommends libsundials-dev libclang1-14 \
     libclang-common-14-dev pkg-config`";

/// The header processed by bindgen and the C shim, relative to the crate root.
const HEADER: &str = "vendor-headers/jointrom_sundials.h";
const SHIM: &str = "vendor-headers/jointrom_sundials.c";

/// Makes every integer macro a `c_int`, as `sundials-sys` does for the `CV`, `SUN`, ... prefixes:
/// the return codes (`CVDIAG_SUCCESS`, ...) are then comparable with the functions' results.
#[derive(Debug)]
struct IntMacrosAsCInt;

impl bindgen::callbacks::ParseCallbacks for IntMacrosAsCInt {
    fn int_macro(&self, _name: &str, _value: i64) -> Option<bindgen::callbacks::IntKind> {
        Some(bindgen::callbacks::IntKind::Int)
    }
}

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed={HEADER}");
    println!("cargo:rerun-if-changed={SHIM}");
    println!("cargo:rerun-if-env-changed=SUNDIALS_INCLUDE_DIR");

    let include = sundials_include_dir();
    let version = header_version(&include);
    if version.0 != 6 {
        panic!(
            "jointrom needs SUNDIALS 6.x, but {} declares version {}.{}.{} \
             (point SUNDIALS_INCLUDE_DIR at SUNDIALS 6 headers, or {APT_HINT})",
            include.join("sundials/sundials_config.h").display(),
            version.0,
            version.1,
            version.2
        );
    }
    // Extra -I only for a non-default location: `-I/usr/include` would demote a system directory.
    let extra_include = (include != Path::new("/usr/include")).then_some(include.as_path());

    let out_dir = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    generate_bindings(extra_include, &out_dir.join("jointrom_sundials.rs"));

    let mut shim = cc::Build::new();
    shim.file(SHIM).include("vendor-headers").warnings(true);
    if let Some(dir) = extra_include {
        shim.include(dir);
    }
    shim.compile("jointrom_sundials");
}

/// The directory holding `sundials/sundials_config.h`.
fn sundials_include_dir() -> PathBuf {
    let probe = Path::new("sundials/sundials_config.h");
    if let Some(dir) = env::var_os("SUNDIALS_INCLUDE_DIR") {
        let dir = PathBuf::from(dir);
        if !dir.join(probe).is_file() {
            panic!(
                "SUNDIALS_INCLUDE_DIR={} has no {} (unset it to use the system headers; {APT_HINT})",
                dir.display(),
                probe.display()
            );
        }
        return dir;
    }
    let candidates = ["/usr/include", "/usr/local/include"];
    for dir in candidates {
        let dir = PathBuf::from(dir);
        if dir.join(probe).is_file() && dir.join("cvode/cvode.h").is_file() {
            return dir;
        }
    }
    panic!(
        "SUNDIALS 6 headers not found: no {} and cvode/cvode.h in {} \
         (set SUNDIALS_INCLUDE_DIR for another location; {APT_HINT})",
        probe.display(),
        candidates.join(" or ")
    );
}

/// `SUNDIALS_VERSION_MAJOR/MINOR/PATCH` as `#define`d in `sundials_config.h` (−1 if absent).
fn header_version(include: &Path) -> (i64, i64, i64) {
    let file = include.join("sundials/sundials_config.h");
    let text = std::fs::read_to_string(&file)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", file.display()));
    let get = |name: &str| {
        text.lines()
            .filter_map(|line| {
                let mut words = line.split_whitespace();
                (words.next() == Some("#define") && words.next() == Some(name))
                    .then(|| words.next()?.parse().ok())
                    .flatten()
            })
            .next()
            .unwrap_or(-1)
    };
    (
        get("SUNDIALS_VERSION_MAJOR"),
        get("SUNDIALS_VERSION_MINOR"),
        get("SUNDIALS_VERSION_PATCH"),
    )
}

/// Runs bindgen on [`HEADER`] and writes the bindings to `out`.
fn generate_bindings(extra_include: Option<&Path>, out: &Path) {
    let mut builder = bindgen::Builder::default()
        .header(HEADER)
        .clang_arg("-Ivendor-headers")
        // Only what sundials-sys lacks; referenced types come from sundials-sys.
        .allowlist_file(r".*[/\\]jointrom_sundials\.h")
        .allowlist_file(r".*[/\\]sundials[/\\]sundials_version\.h")
        .allowlist_file(r".*[/\\]cvode[/\\]cvode_diag\.h")
        .allowlist_file(r".*[/\\]cvode[/\\]cvode_bandpre\.h")
        .allowlist_file(
            r".*[/\\]arkode[/\\]arkode(_arkstep|_ls|_butcher|_butcher_dirk|_butcher_erk)?\.h",
        )
        .allowlist_var("SUNDIALS_VERSION_(MAJOR|MINOR|PATCH)")
        .allowlist_recursively(false)
        .parse_callbacks(Box::new(IntMacrosAsCInt))
        .parse_callbacks(Box::new(bindgen::CargoCallbacks))
        .merge_extern_blocks(true)
        .layout_tests(false);
    if let Some(dir) = extra_include {
        builder = builder.clang_arg(format!("-I{}", dir.display()));
    }
    // bindgen panics (rather than returning an error) when it cannot load libclang.
    let generated = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| builder.generate()));
    let bindings = match generated {
        Ok(Ok(bindings)) => bindings,
        Ok(Err(e)) => panic!(
            "bindgen failed on {HEADER}: {e} (a missing `stddef.h` means the clang resource \
             headers are missing; {APT_HINT})"
        ),
        Err(_) => panic!("bindgen could not run, most likely libclang was not found ({APT_HINT})"),
    };
    bindings
        .write_to_file(out)
        .unwrap_or_else(|e| panic!("cannot write {}: {e}", out.display()));
}
