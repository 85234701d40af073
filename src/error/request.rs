//! Requests that do not fit the model, one enum per layer: each variant names what was asked
//! and why it cannot be done. All are shown after `invalid request: `.

use std::path::PathBuf;

/// A model request that does not fit (the `model` layer).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ModelError {
    /// `export-matrices`: DOF `dof` of node `node` depends on several DOF without the node being
    /// a rigid follower of the master node.
    #[error(
        "export-matrices: node {node} DOF {dof} depends on several DOF but is not a rigid \
         follower of the master node; the map cannot express it"
    )]
    ExportDependentDof { node: u64, dof: usize },
    /// `export-matrices`: no node owns the six master DOF.
    #[error("export-matrices: no node owns the six master DOF")]
    ExportNoMasterNode,
    /// A CGAP of the deck `file` joins two coincident nodes.
    #[error("{}: a degenerate CGAP", file.display())]
    DegenerateGap { file: PathBuf },
}

/// A joint or contact-statics request that does not fit (the `joint` layer).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum JointError {
    /// The contact normal stiffness `k_n` (N/mm) is not finite and positive.
    #[error("contact normal stiffness must be finite and positive, got {k_n} N/mm")]
    NormalStiffness { k_n: f64 },
    /// The contact options ask for no iteration.
    #[error("contact options: max_iterations must be at least 1")]
    NoIterations,
    /// Contact statics: K (`n` × `n`), the joint operator (`joint_dofs` columns) and the load
    /// (`load` entries) do not fit.
    #[error(
        "contact statics: K is {n}×{n}, the joint operator has {joint_dofs} columns and the load \
         {load} entries"
    )]
    StaticsSizes {
        n: usize,
        joint_dofs: usize,
        load: usize,
    },
    /// Reduced contact statics: `K_r`, `B_n Φ` (rows × columns) and `f_r` do not fit.
    #[error(
        "reduced contact statics: K_r is {}×{}, B_n Φ is {}×{}, f_r has {load} entries",
        k_r.0,
        k_r.1,
        b_n_phi.0,
        b_n_phi.1
    )]
    ReducedStaticsSizes {
        k_r: (usize, usize),
        b_n_phi: (usize, usize),
        load: usize,
    },
    /// Joint pair `pair` names the node index `node`, which does not exist.
    #[error("joint pair {pair} names node {node}, which does not exist")]
    UnknownNode { pair: usize, node: usize },
    /// Joint pair `pair`: node `node` has no independent translation along `axis`.
    #[error(
        "joint pair {pair}: node {node} has no independent {axis} translation (clamped or not \
         in the matrices); a joint node must move"
    )]
    FixedNode {
        pair: usize,
        node: usize,
        axis: &'static str,
    },
}

/// A reduced-model request that does not fit (the `system` layer).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SystemError {
    /// A basis of `rows` rows for a model of `dofs` DOF.
    #[error("basis has {rows} rows, the model {dofs} DOF")]
    BasisRows { rows: usize, dofs: usize },
    /// A basis of `columns` columns for a reduced model of dimension `r`.
    #[error("basis has {columns} columns, the reduced model dimension {r}")]
    BasisColumns { columns: usize, r: usize },
    /// The reduced matrices' sizes (rows × columns) do not fit the dimension `r`.
    #[error(
        "reduced model of dimension {r} has inconsistent K̃ ({}×{}), M̃ ({}×{}), BΦ ({}×{}, 3 rows \
         per pair), master rows ({}×{}) or coordinate sizes ({coordinates})",
        k.0,
        k.1,
        m.0,
        m.1,
        b_phi.0,
        b_phi.1,
        master.0,
        master.1
    )]
    Sizes {
        r: usize,
        k: (usize, usize),
        m: (usize, usize),
        b_phi: (usize, usize),
        master: (usize, usize),
        coordinates: usize,
    },
    /// The reduced matrix `name` (`K̃`, `M̃`, `BΦ`, `master rows`) has a NaN or Inf.
    #[error("reduced model: {name} has a non-finite entry")]
    NotFinite { name: &'static str },
    /// Basis column `column` is zero or not finite.
    #[error("basis column {column} is zero or not finite")]
    ZeroColumn { column: usize },
    /// A reduced model of dimension `r` of a field with only `field_dofs` DOF.
    #[error("reduced model of dimension {r} of a field with fewer DOF ({field_dofs})")]
    FieldTooSmall { r: usize, field_dofs: usize },
}

/// A reduction request that does not fit the model (the `reduction` layer).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ReductionError {
    /// `what` (a basis, TVD base, snapshots) has `rows` rows, the model `dofs` DOF.
    #[error("{what} {rows} rows, the model {dofs} DOF")]
    Rows {
        /// The matrix with its verb, e.g. `basis has`, `snapshots have`.
        what: &'static str,
        rows: usize,
        dofs: usize,
    },
    /// The secant TVD asked for together with the tangential or inertia variant.
    #[error("secant TVD: only the static normal-stiffness TVD have a secant form (no tangential, no inertia)")]
    SecantOptions,
    /// A basis part of `rows` rows for an `n` × `n` mass matrix.
    #[error("basis part has {rows} rows, the mass matrix is {n}×{n}")]
    PartRows { rows: usize, n: usize },
    /// `what` (a basis column, POD vectors) is not finite.
    #[error("{what} not finite")]
    NotFinite {
        /// The quantity with its verb, e.g. `POD: the vectors are`.
        what: &'static str,
    },
    /// The POD weight (`n` × `n`) does not fit vectors of `rows` rows.
    #[error("POD weight is {n}×{n}, the vectors have {rows} rows")]
    PodWeight { n: usize, rows: usize },
    /// The TVD factor form (flexibility rows × columns times `m` × `p`) does not fit the
    /// vectors (`n` × `columns`).
    #[error(
        "TVD factor form is {}×{} times {m}×{p}, the vectors {n}×{columns}",
        flexibility.0,
        flexibility.1
    )]
    TvdFactorForm {
        flexibility: (usize, usize),
        m: usize,
        p: usize,
        n: usize,
        columns: usize,
    },
    /// A TVD zero tolerance outside [0, 1).
    #[error("TVD zero tolerance must be in [0, 1), got {tol}")]
    TvdTolerance { tol: f64 },
    /// TVD base vector `vector` has the Rayleigh quotient `omega2`.
    #[error(
        "TVD with inertia: base vector {vector} has Rayleigh quotient {omega2:e} (zero vector?)"
    )]
    TvdRayleighQuotient { vector: usize, omega2: f64 },
    /// Snapshot POD without snapshots.
    #[error("snapshot POD: no snapshots (0 columns)")]
    NoSnapshots,
    /// Snapshot `snapshot`, DOF `dof` is NaN or infinite.
    #[error("snapshot POD: snapshot {snapshot}, DOF {dof} is not finite")]
    SnapshotNotFinite { snapshot: usize, dof: usize },
    /// A joint pair names the node index `node`, which does not exist.
    #[error("joint pair names node {node}, which does not exist")]
    UnknownJointNode { node: usize },
    /// Joint node `node`, direction `axis` is not an independent interior DOF.
    #[error(
        "Joint Interface Modes: joint node {node}, direction {axis} is not an independent \
         interior DOF (clamped, tied or the master node)"
    )]
    JimDependentDof { node: usize, axis: &'static str },
    /// `method` needs interior DOF; the model has only `dofs` DOF.
    #[error("{method} needs interior DOF: the model has only {dofs} DOF")]
    NoInteriorDofs { method: &'static str, dofs: usize },
    /// `method` expects the master DOF last: master DOF `master` is independent DOF `dof`,
    /// not `expected`.
    #[error(
        "{method} expects the master DOF last: master DOF {master} is independent DOF {dof}, not \
         {expected}"
    )]
    MasterNotLast {
        method: &'static str,
        master: usize,
        dof: usize,
        expected: usize,
    },
    /// `count` Joint Interface Modes asked of the `set` set with `available` joint DOF.
    #[error("{count} Joint Interface Modes requested, the {set} set has {available} joint DOF")]
    JimCount {
        count: usize,
        set: &'static str,
        available: usize,
    },
    /// `--nu nu` fixed-interface modes asked of a model with `interior` interior DOF.
    #[error(
        "--nu {nu}: the model has only {interior} interior DOF, so at most {interior} \
         fixed-interface modes"
    )]
    FixedInterfaceModes { nu: usize, interior: usize },
    /// The distributed reference of `case` has no TVD right-hand sides.
    #[error("distributed: {case} has no TVD right-hand sides (no joint pair is ever active)")]
    NoTvdRhs {
        /// The case's name, printable.
        case: String,
    },
    /// The distributed job manifest did not serialise.
    #[error("distributed: job manifest: {source}")]
    JobManifest {
        #[source]
        source: serde_json::Error,
    },
    /// The error estimate needs the basis Φ, which a reduced model read from a file lacks.
    #[error("error estimate: the reduced model carries no basis Φ (read from a file)")]
    EstimateNoBasis,
    /// The error estimate's model (`dofs` DOF, `pairs` pairs) does not fit the basis
    /// (rows × columns, `basis_pairs` pairs).
    #[error(
        "error estimate: basis {}×{} with {basis_pairs} pairs does not fit the model ({dofs} \
         DOF, {pairs} pairs)",
        basis.0,
        basis.1
    )]
    EstimateBasis {
        basis: (usize, usize),
        basis_pairs: usize,
        dofs: usize,
        pairs: usize,
    },
    /// The run states do not fit `outputs` outputs of a model with `r` coordinates and `w`
    /// pairs.
    #[error("error estimate: run states do not fit {outputs} outputs of r = {r}, w = {w}")]
    EstimateStates { outputs: usize, r: usize, w: usize },
    /// The reduced acceleration at `t` (s) is not finite (`value`).
    #[error("error estimate: reduced acceleration at t = {t:e} s is not finite ({value})")]
    EstimateAcceleration { t: f64, value: f64 },
}

/// A time-integration request that does not fit (the `integrate` layer).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum IntegrationError {
    /// A start time (s) that is not finite.
    #[error("the start time must be finite, got {t0} s")]
    StartTime { t0: f64 },
    /// A step to `t_next` that does not end after the current time `t` (s).
    #[error("a step must end after the current time {t} s, got {t_next} s")]
    StepEnd { t: f64, t_next: f64 },
    /// The run's `what` (an output) is not finite at `t` (s).
    #[error(
        "the run's {what} is not finite at t = {t} s (an overflow: check k_n, k_t and the load)"
    )]
    OutputNotFinite { what: &'static str, t: f64 },
    /// A vector length beyond SUNDIALS's index type.
    #[error("vector length {len} exceeds SUNDIALS's index type")]
    VectorLength { len: usize },
    /// The problem's absolute-tolerance scale entry `index` is not finite and positive.
    #[error("the problem's absolute-tolerance scale[{index}] = {value} is not finite and > 0")]
    ToleranceScale { index: usize, value: f64 },
    /// A count (`what = value`) too large for a C int.
    #[error("{what} = {value} is too large")]
    TooLarge { what: &'static str, value: usize },
    /// `function`'s time argument `name = value` is not finite.
    #[error("{function}: {name} = {value} is not finite")]
    TimeNotFinite {
        function: &'static str,
        name: &'static str,
        value: f64,
    },
    /// `set_root_direction` got `directions`, not `roots` entries of −1, 0, +1.
    #[error("set_root_direction: need {roots} entries of -1, 0, +1, got {directions:?}")]
    RootDirections { roots: usize, directions: Vec<i32> },
    /// `function`: a state `y` of `len` entries for a problem of dimension `n`.
    #[error("{function}: y has {len} entries, the problem's dimension is {n}")]
    StateLength {
        function: &'static str,
        len: usize,
        n: usize,
    },
    /// `function`: `y[index] = value` is not finite.
    #[error("{function}: y[{index}] = {value} is not finite")]
    StateNotFinite {
        function: &'static str,
        index: usize,
        value: f64,
    },
    /// A problem of dimension 0.
    #[error("Cvode::new: the problem has dimension 0")]
    EmptyProblem,
    /// The option `field` has the value `value` (as text); it must be `need`.
    #[error("OdeOptions.{field} = {value}: must be {need}")]
    Option {
        field: &'static str,
        value: String,
        need: String,
    },
}

/// A report that cannot be written as asked (the `report` layer).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ReportError {
    /// A VTU shape name with characters other than ASCII letters, digits, `_`, `-` (or empty).
    #[error("VTU shape name `{name}` must be non-empty ASCII letters, digits, `_` or `-`")]
    VtuName { name: String },
    /// `what` has `rows` rows, the model `dofs` DOF.
    #[error("{what} have {rows} rows, the model {dofs} DOF")]
    Rows {
        /// E.g. `VTU: shapes`, `joint-mode picture: modes`.
        what: &'static str,
        rows: usize,
        dofs: usize,
    },
    /// Column `column`, DOF `dof` of the VTU shapes `prefix` is not finite.
    #[error("VTU: {prefix} column {column}, DOF {dof} is not finite")]
    VtuNotFinite {
        prefix: String,
        column: usize,
        dof: usize,
    },
    /// A VTU series of `times` times and `states` states.
    #[error("VTU series: {times} times but {states} states")]
    SeriesLength { times: usize, states: usize },
    /// State `state` of a VTU series has `len` entries, the model `dofs` DOF.
    #[error("VTU series: state {state} has {len} entries, the model {dofs} DOF")]
    SeriesState {
        state: usize,
        len: usize,
        dofs: usize,
    },
    /// State `state` (at `t`, s) of a VTU series is not finite.
    #[error("VTU series: state {state} (t = {t} s) is not finite")]
    SeriesNotFinite { state: usize, t: f64 },
    /// The FMU archive could not be written (`what`: the entry).
    #[error("writing the FMU archive ({what}): {source}")]
    FmuArchive {
        what: String,
        #[source]
        source: zip::result::ZipError,
    },
    /// The FMU binary `binary` is not a 64-bit ELF shared object.
    #[error(
        "the FMU binary {} is not a 64-bit ELF shared object (expected the libjointrom_fmu.so \
         built by `cargo build --release -p jointrom-fmu`)",
        binary.display()
    )]
    FmuBinary { binary: PathBuf },
    /// `curves.csv` could not be formatted: the CSV writer's error (or the text's UTF-8 check).
    #[error("curves.csv: {source}")]
    Curves {
        #[source]
        source: Box<dyn std::error::Error + Send + Sync + 'static>,
    },
    /// Heat map `title`: `rows` rows of cells, `labels` row labels.
    #[error("heat map \"{title}\": {rows} rows of cells, {labels} row labels")]
    HeatMapRows {
        title: String,
        rows: usize,
        labels: usize,
    },
    /// Heat map `title`: row `row` has `cells` cells, `labels` column labels.
    #[error("heat map \"{title}\": row {row} has {cells} cells, {labels} column labels")]
    HeatMapRow {
        title: String,
        row: usize,
        cells: usize,
        labels: usize,
    },
    /// Heat map `title` with a zero cell size.
    #[error("heat map \"{title}\": zero cell size")]
    HeatMapCellSize { title: String },
    /// The chart font could not be loaded.
    #[error(transparent)]
    Font(#[from] FontError),
}

/// Why the chart font could not be loaded (kept for the process: clonable).
#[derive(Clone, Debug, thiserror::Error)]
#[non_exhaustive]
pub enum FontError {
    /// No font is set and none of the `candidates` exists.
    #[error(
        "charts need a TrueType font: none of {} exists; install Debian's fonts-dejavu-core or \
         set JOINTROM_FONT to a .ttf file",
        candidates.join(", ")
    )]
    Missing { candidates: &'static [&'static str] },
    /// The font `file` could not be read (`reason`: the OS error's text).
    #[error("chart font {}: cannot read: {reason}", file.display())]
    Unreadable { file: PathBuf, reason: String },
    /// The font `file` is not a TrueType/OpenType font.
    #[error("chart font {}: not a valid TrueType/OpenType font", file.display())]
    Invalid { file: PathBuf },
}
