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
    /// `export-matrices`: the model's contact points lie inside the joint's faces, which a
    /// map's node pairs cannot express.
    #[error(
        "export-matrices: the contact is sampled at points inside the joint's faces \
         (`contact.sampling`); a matrix map holds node pairs only: export the case without \
         `sampling`"
    )]
    ExportContactPoints,
    /// `export-matrices`: no node owns the six master DOF.
    #[error("export-matrices: no node owns the six master DOF")]
    ExportNoMasterNode,
    /// A contact law per area cannot be resolved on the model from `model`: `field` names the
    /// file's field or the flag that asked for it.
    #[error("{model}: `{field}`: {reason}")]
    PerArea {
        model: String,
        field: String,
        reason: String,
    },
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
    /// A basis name that is none of the `valid` ones.
    #[error("unknown basis `{name}`: expected one of {}", valid.join(", "))]
    UnknownBasis {
        name: String,
        valid: &'static [&'static str],
    },
    /// The basis kind `kind` has no TVD POD.
    #[error("basis `{kind}` has no TVD POD: expected tvd or tvd-plain")]
    NoTvdPod { kind: &'static str },
    /// `--g g` beyond the `available` modes of the TVD's POD on `model` (printable).
    #[error("--g {g}: the POD of the TVD has only {available} modes on {model}")]
    PodModes {
        g: usize,
        available: usize,
        model: String,
    },
    /// The distributed PETSc program `program` does not exist (`var`: the variable naming it).
    #[error(
        "--program: the PETSc program {} does not exist; build it with `scripts/dist.sh build` \
         (needs `apt-get install -y slepc-dev openmpi-bin`), or name it with --program or ${var}",
        program.display()
    )]
    DistributedProgram { program: PathBuf, var: &'static str },
    /// `mpirun -n ranks program` ended with `status`; `stderr` is the tail of its error output
    /// (printable).
    #[error("{mpirun} -n {ranks} {}: {status}\n{stderr}", program.display())]
    DistributedFailed {
        mpirun: String,
        ranks: usize,
        program: PathBuf,
        status: String,
        stderr: String,
    },
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
    /// An initial state whose block `what` (q, v or the slip memory) has `len` entries where
    /// the problem has `need`, or a non-finite entry (`len == need`).
    #[error("initial state: {what} has {len} entries (need {need}) or a non-finite one")]
    InitialState {
        what: &'static str,
        len: usize,
        need: usize,
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
    /// A time `what` (e.g. `end_time`) that is not finite and positive (`value`, s).
    #[error("{what} must be finite and positive, got {value} s")]
    NotPositive { what: &'static str, value: f64 },
    /// A problem scale `name` (e.g. `slip_scale`) that is not finite and positive.
    #[error("{name} must be finite and positive, got {value}")]
    ScaleNotPositive { name: &'static str, value: f64 },
    /// A load scale that is not finite.
    #[error("the load scale must be finite, got {scale}")]
    LoadScale { scale: f64 },
    /// A master load component (`Fx` … `Mz`) that is not finite.
    #[error("the master load component {component} must be finite, got {value}")]
    LoadComponent { component: &'static str, value: f64 },
    /// `end / output_step` gives `outputs` output points, more than the `max` a run keeps.
    #[error(
        "end time {end:e} s / output step {output_step:e} s = {outputs:e} output points, more \
         than the {max:e} a run keeps: raise --output-step or lower --end-time"
    )]
    TooManyOutputs {
        end: f64,
        output_step: f64,
        outputs: f64,
        max: f64,
    },
    /// A run stopped at `t` (s) because it crawls: `reason` says which statistic and the flag to
    /// change.
    #[error("the run was stopped at t = {t:.6e} s, it cannot finish in reasonable time: {reason}")]
    Stalled { t: f64, reason: String },
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
    /// The variable `var` names `path`, which is not a file (`file`: the FMU binary's name).
    #[error(
        "{var}={} is not a file (point it at the {file} built by `cargo build --release -p \
         jointrom-fmu`, or unset it)",
        path.display()
    )]
    FmuBinaryEnv {
        var: &'static str,
        path: PathBuf,
        file: &'static str,
    },
    /// The running executable could not be located to find the FMU binary `file` beside it.
    #[error("--fmu: cannot locate this executable to find {file} beside it ({source}); set {var}")]
    FmuNoExecutable {
        file: &'static str,
        var: &'static str,
        #[source]
        source: std::io::Error,
    },
    /// The FMU binary `path` beside the executable does not exist.
    #[error(
        "--fmu: the FMU binary {} does not exist: build it with `cargo build --release -p \
         jointrom-fmu` (it lands beside the jointrom executable), or set {var} to it",
        path.display()
    )]
    FmuBinaryMissing { path: PathBuf, var: &'static str },
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

/// A command-line flag with a value it cannot take (the CLI and the library checks that name
/// a flag). `flag` is the flag's name without the leading `--`.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum FlagError {
    /// A value that must be finite and positive.
    #[error("--{flag} must be finite and positive, got {value}")]
    NotPositive { flag: &'static str, value: f64 },
    /// A value that must be finite.
    #[error("--{flag} must be finite, got {value}")]
    NotFinite { flag: &'static str, value: f64 },
    /// A value outside what the flag accepts: `need` says what it accepts, `got` is the value
    /// as shown (quoted where the flag's text is).
    #[error("--{flag} must be {need}, got {got}")]
    Range {
        flag: &'static str,
        need: &'static str,
        got: String,
    },
    /// A count below `min`.
    #[error("--{flag} must be at least {min}")]
    AtLeast { flag: &'static str, min: usize },
    /// A value (as shown) the flag does not take: `need` says which it takes.
    #[error("--{flag} {value}: {need}")]
    Value {
        flag: &'static str,
        value: String,
        need: &'static str,
    },
    /// An unknown name of a `what` (e.g. `model`) among the `valid` ones.
    #[error("--{flag}: unknown {what} {value:?}; valid: {valid}")]
    Unknown {
        flag: &'static str,
        what: &'static str,
        value: String,
        valid: &'static str,
    },
    /// An unknown basis kind among the `valid` names.
    #[error("--{flag} {value:?}: unknown basis kind; valid: {}", valid.join(", "))]
    UnknownBasis {
        flag: &'static str,
        value: String,
        valid: &'static [&'static str],
    },
    /// A basis name the reduction does not know.
    #[error("--{flag}: invalid request: {source}")]
    Basis {
        flag: &'static str,
        #[source]
        source: ReductionError,
    },
    /// A switch that is neither `on` nor `off`.
    #[error("--{flag}: expected on or off, got {value:?}")]
    OnOff { flag: &'static str, value: String },
    /// No rank count, or a zero one.
    #[error("--ranks: give one or more positive rank counts, e.g. 1,2")]
    Ranks,
}

/// A model choice or reduced-model request that does not fit (the `rom` layer).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RomError {
    /// `--model` and `--basis` both given.
    #[error("--model and --basis both name the model: give one of them")]
    ModelAndBasis,
    /// `--model` names no model.
    #[error("--model: invalid request: {source} (or full, pod)")]
    ModelName {
        #[source]
        source: ReductionError,
    },
    /// `--tolerance` and `--g` both given.
    #[error("--tolerance and --g both size the model: give one of them")]
    ToleranceAndG,
    /// `--tolerance` beside a model it does not build (`model`: the flag naming it).
    #[error(
        "--tolerance builds its own model (--model adaptive); it does not apply to {model} (use \
         --g to size that one)"
    )]
    ToleranceModel { model: String },
    /// `--g` without a reduced model.
    #[error("--g needs --basis (or --model)")]
    GWithoutBasis,
    /// `--g` with `--model full`.
    #[error("--g applies to reduced models, not --model full")]
    GOnFull,
    /// `--g` or `--train-end` with a reduced model read from a file.
    #[error("--g and --train-end do not apply to --model file:PATH")]
    FileSizing,
    /// `--model adaptive` without `--tolerance`.
    #[error("--model adaptive is chosen by --tolerance TOL: give the tolerance")]
    AdaptiveWithoutTolerance,
    /// `--train-end` with a model other than POD.
    #[error("--train-end applies to --model pod only")]
    TrainEndNotPod,
    /// `--low-rank` with a reduced model.
    #[error("--low-rank applies to --model full (the reduced model refactors its dense matrix)")]
    LowRankReduced,
    /// `--linear` with a reduced model.
    #[error(
        "--linear and a reduced model do not combine: a reduced model solves the contact statics \
         (drop --linear, or --basis/--model/--tolerance)"
    )]
    LinearReduced,
    /// `--vtu` with a reduced model read from a file (no basis Φ).
    #[error(
        "--vtu needs the basis Φ, which an exported reduced model does not carry; run the basis \
         by name instead (e.g. --model tvd)"
    )]
    VtuFromFile,
    /// `command` cannot use the model `model`; it takes `takes`.
    #[error("{command} does not take --model {model}: it takes {takes}")]
    Unsupported {
        command: String,
        model: String,
        takes: &'static str,
    },
    /// A tolerance that is not a relative error in (0, 1).
    #[error("--tolerance must be a relative error in (0, 1), got {tolerance}")]
    Tolerance { tolerance: f64 },
    /// `--tolerance-on` names a quantity that does not exist (`name`, printable).
    #[error(
        "--tolerance-on: unknown quantity `{name}` (a comma-separated list of fc, fr, uy, \
         dissipation)"
    )]
    ToleranceOnName { name: String },
    /// `--tolerance-on` on `static` with anything but `fc`.
    #[error("--tolerance-on: static --tolerance controls |f_c| only (give fc, or drop the flag)")]
    ToleranceOnStatic,
    /// `--tolerance-on` with an empty list.
    #[error("--tolerance-on: the list is empty (give some of fc, fr, uy, dissipation)")]
    ToleranceOnEmpty,
    /// `--tolerance-on` without `--tolerance`.
    #[error("--tolerance-on selects what --tolerance controls: give --tolerance TOL too")]
    ToleranceOnWithout,
    /// `--tolerance-on` names a quantity (`name`) the run does not produce: friction is off.
    #[error(
        "--tolerance-on {name}: the run has friction off, so it has no {what}; drop `{name}` or \
         turn friction on"
    )]
    ToleranceOnFriction {
        name: &'static str,
        what: &'static str,
    },
    /// Fewer than two POD snapshots.
    #[error("--snapshots must be at least 2, got {snapshots}")]
    Snapshots { snapshots: usize },
    /// `--strict`: the best model's largest estimated error (of the quantities of
    /// `--tolerance-on`) misses `--tolerance`.
    #[error(
        "--strict: the estimated error {estimate:e} of the best model exceeds --tolerance \
         {tolerance:e} (the result above is that model's)"
    )]
    Strict { estimate: f64, tolerance: f64 },
    /// A reference curves file (`file`, as shown) that cannot be used.
    #[error("reference {file}: {problem}")]
    Reference {
        file: String,
        problem: ReferenceProblem,
    },
    /// The reduced model of `file` was exported from the case `exported_from` (printable), not
    /// from the one given: `differs` says what differs.
    #[error(
        "{}: this reduced model was exported from `{exported_from}`, not from the CASE given \
         ({differs}): give the case it was exported from",
        file.display()
    )]
    SourceMismatch {
        file: PathBuf,
        exported_from: String,
        differs: String,
    },
    /// A reduced model that carries neither its model nor its file.
    #[error("a reduced model without its model or file")]
    Detached,
    /// No error estimate: the run ended early with `status`.
    #[error("no error estimate: the run ended early ({status})")]
    EstimateEarlyEnd { status: String },
}

/// What is wrong with a reference curves file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ReferenceProblem {
    /// The CSV reader failed.
    #[error("{0}")]
    Csv(#[source] csv::Error),
    /// The JSON did not parse.
    #[error("{0}")]
    Json(#[source] serde_json::Error),
    /// The CSV header has no column `name`.
    #[error("no column `{name}` in the header")]
    NoColumn { name: &'static str },
    /// A CSV cell (printable) that is not a finite number, on line `line`.
    #[error("line {line}: `{cell}` is not a finite number")]
    NotFinite { line: usize, cell: String },
    /// The JSON has no array `name`.
    #[error("no array `{name}`")]
    NoArray { name: &'static str },
    /// The JSON array `name` holds a value that is not a finite number.
    #[error("`{name}` holds a value that is not a number")]
    NotNumber { name: &'static str },
    /// The curves have different lengths.
    #[error("the curves have different lengths")]
    Lengths,
    /// Fewer than two outputs.
    #[error("{outputs} outputs; at least 2 are needed")]
    TooFew { outputs: usize },
    /// The time at output `output` (s) does not exceed the one before.
    #[error("times do not increase at output {output}: {t} s after {previous} s")]
    NotIncreasing {
        output: usize,
        t: f64,
        previous: f64,
    },
}

/// A study request that does not fit, or a study that cannot go on (the `studies` layer).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum StudyError {
    /// `--g g` beyond the `available` enrichment vectors of the basis `basis` on `model`.
    #[error("--g {g}: basis `{basis}` has only {available} enrichment vectors on {model}")]
    Enrichment {
        g: usize,
        basis: &'static str,
        available: usize,
        model: String,
    },
    /// A POD threshold outside (0, 1].
    #[error("threshold must be in (0, 1], got {threshold}")]
    Threshold { threshold: f64 },
    /// The full model of `model` has no pair in contact under the load.
    #[error(
        "{model}: the full model has no pair in contact under this load (‖f_c‖ = 0), so there is \
         no contact force to converge to; try --scale -1"
    )]
    NoContact { model: String },
    /// The convergence study gave no K-weighted TVD energy curve.
    #[error("the study has no K-weighted TVD energy curve")]
    NoTvdEnergy,
    /// The full FE reference run failed at `t` (s) with `status` and `message`.
    #[error("the full FE reference run failed at t = {t} s ({status}): {message}")]
    ReferenceFailed {
        t: f64,
        status: String,
        message: String,
    },
    /// A stability map option that must be finite and positive.
    #[error("{option} must be finite and positive, got {value}")]
    NotPositive { option: String, value: f64 },
    /// `--modes mode` beyond the `available` modes of the model `model`.
    #[error("--modes {mode}: the {model} model has only {available} modes")]
    ModeBeyond {
        mode: usize,
        available: usize,
        model: String,
    },
    /// A stability map reference factor below 1.
    #[error("reference_factor must be ≥ 1, got {factor}")]
    ReferenceFactor { factor: f64 },
    /// A stability map BDF order outside 1–5.
    #[error("max_orders: BDF order must be 1–5, got {order}")]
    MaxOrder { order: usize },
    /// A stability map without steps.
    #[error("max_steps must be positive")]
    MaxSteps,
    /// A stability map axis without values.
    #[error("every sweep axis needs at least one value")]
    EmptyAxis,
    /// Sweep variants failed: their names (printable) of `total`.
    #[error(
        "{} of {total} sweep variants failed: {}",
        failed.len(),
        failed.iter().map(|n| format!("`{n}`")).collect::<Vec<_>>().join(", ")
    )]
    SweepFailed { failed: Vec<String>, total: usize },
    /// The JSON document of the study could not be written.
    #[error("JSON output: {0}")]
    JsonOutput(#[source] serde_json::Error),
}
