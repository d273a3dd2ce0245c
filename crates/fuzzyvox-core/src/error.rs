//! The library's error type: every fallible public function returns [`Result`].

use std::path::PathBuf;

use crate::ops::OperatorError;

/// What went wrong, typed so that callers can react to each case.
///
/// A failed call never leaves a map half-updated: every integration validates its whole input
/// before it changes anything.
///
/// Every fuzzyvox crate's errors convert into it: [`OperatorError`] through
/// [`Error::Operator`], and the planner's `PlanError` (`fuzzyvox-plan`) through
/// [`Error::Plan`]. New variants may be added, so matches need a wildcard arm.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A value that must be finite was NaN or infinite.
    #[error("{what} must be finite, got {value}")]
    NonFinite {
        /// Which value.
        what: &'static str,
        /// The offending value.
        value: f64,
    },
    /// A numeric parameter is outside its valid range.
    #[error("{name} = {value} is invalid: expected {expected}")]
    InvalidParameter {
        /// Parameter name.
        name: &'static str,
        /// The offending value.
        value: f64,
        /// The valid range, in words.
        expected: &'static str,
    },
    /// A point lies outside the range that `i32` voxel keys can address at this resolution.
    #[error(
        "point ({x}, {y}, {z}) is outside the addressable key range at resolution {resolution} m"
    )]
    OutOfKeyRange {
        /// x coordinate (m).
        x: f64,
        /// y coordinate (m).
        y: f64,
        /// z coordinate (m).
        z: f64,
        /// Map resolution (m).
        resolution: f64,
    },
    /// A pose is not a proper rigid transform (non-finite, or a rotation that is not orthonormal).
    #[error("invalid pose: {0}")]
    InvalidPose(String),
    /// Two inputs that must agree in size do not.
    #[error("size mismatch in {what}: expected {expected}, found {found}")]
    SizeMismatch {
        /// Which input.
        what: &'static str,
        /// Expected length.
        expected: usize,
        /// Actual length.
        found: usize,
    },
    /// An input that must hold data is empty.
    #[error("{0} is empty")]
    Empty(&'static str),
    /// A confidence value lies outside `[0, 1]`.
    #[error("confidence at index {index} is {value}, outside [0, 1]")]
    InvalidConfidence {
        /// Index of the point or pixel.
        index: usize,
        /// The offending value.
        value: f32,
    },
    /// A depth interval is out of order (`P- <= P0 <= P+` must hold).
    #[error("depth interval at pixel ({x}, {y}) is out of order: {near} <= {depth} <= {far} fails")]
    IntervalOrder {
        /// Pixel column.
        x: u32,
        /// Pixel row.
        y: u32,
        /// `P-` (m).
        near: f32,
        /// `P0` (m).
        depth: f32,
        /// `P+` (m).
        far: f32,
    },
    /// A stereo pair cannot be rectified usefully (depth stage).
    #[error("the stereo pair cannot be rectified: {reason}")]
    Unrectifiable {
        /// Why.
        reason: UnrectifiableReason,
    },
    /// An aggregation operator's parameters are invalid or its name unknown.
    #[error(transparent)]
    Operator(#[from] OperatorError),
    /// No path could be planned: the planner's `PlanError` (start or goal unsafe, out of the
    /// region, disconnected), kept whole; `downcast_ref::<fuzzyvox_plan::PlanError>()` reads
    /// it. (A `PlanError` that wraps an [`Error`] converts into that error itself.)
    #[error(transparent)]
    Plan(Box<dyn std::error::Error + Send + Sync + 'static>),
    /// One item of a list that must not repeat was given twice (an experiment's operators).
    #[error("{0} is listed twice")]
    Duplicate(String),
    /// A name (of a map model, a scenario, ...) that is not one of those known.
    #[error("unknown {what} `{name}`: expected {expected}")]
    UnknownName {
        /// What the name should name.
        what: &'static str,
        /// The name given.
        name: String,
        /// The names known.
        expected: &'static str,
    },
    /// Two maps cannot be combined.
    #[error("maps are incompatible: {0}")]
    Incompatible(String),
    /// A file could not be read or written.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
    /// A file is damaged, truncated or of another format.
    #[error("{}: {reason}", path.display())]
    Format {
        /// The file.
        path: PathBuf,
        /// What is wrong with it.
        reason: FormatError,
    },
    /// A text input could not be parsed.
    #[error("{}:{line}: {message}", path.display())]
    Parse {
        /// The file.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// A figure or chart could not be drawn (the message says why).
    #[error("could not draw the figure: {0}")]
    Figure(String),
}

/// Why a map file could not be read.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum FormatError {
    /// The file does not start with fuzzyvox's magic bytes.
    #[error("not a fuzzyvox map file (bad magic bytes)")]
    BadMagic,
    /// The file was written by a newer, unknown format version.
    #[error("unsupported format version {0} (this fuzzyvox reads versions 1 to 5)")]
    UnsupportedVersion(u16),
    /// The file holds another kind of map than the one requested.
    #[error("the file holds a {found} map, not a {expected} map")]
    WrongKind {
        /// The kind the caller asked for.
        expected: &'static str,
        /// The kind the file declares.
        found: String,
    },
    /// The file is shorter or longer than its header declares.
    #[error("length mismatch: header declares {declared} bytes of body, file has {actual}")]
    Length {
        /// Declared body length.
        declared: u64,
        /// Actual body length.
        actual: u64,
    },
    /// The checksum does not match the contents.
    #[error(
        "checksum mismatch (stored {stored:#010x}, computed {computed:#010x}): the file is damaged"
    )]
    Checksum {
        /// CRC stored in the file.
        stored: u32,
        /// CRC of the bytes read.
        computed: u32,
    },
    /// The file is none of the map formats fuzzyvox reads.
    #[error(
        "not a map file fuzzyvox reads: expected a fuzzyvox map (.fvx, starting with \
         `FUZZYVOX`), an OctoMap binary tree (.bt, starting with `# Octomap OcTree binary file`) \
         or an OctoMap tree (.ot, starting with `# Octomap OcTree file`)"
    )]
    UnknownMapFormat,
    /// The body could not be decoded or holds invalid values.
    #[error("invalid contents: {0}")]
    Invalid(String),
}

/// Shorthand for results of this crate.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Returns `value` when it is finite, else a [`Error::NonFinite`] naming `what`.
pub fn finite(what: &'static str, value: f64) -> Result<f64> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(Error::NonFinite { what, value })
    }
}

/// Why a pair cannot be rectified usefully.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum UnrectifiableReason {
    /// The camera centres coincide: there is no parallax to measure depth from.
    #[error("zero baseline ({baseline:.3e} m)")]
    ZeroBaseline {
        /// Distance between the camera centres (m).
        baseline: f64,
    },
    /// One camera's centre projects inside the other's image (motion along the look
    /// direction): the rectifying rotation would map the epipole to infinity inside the image.
    #[error("the epipole of the {camera} camera lies inside its image at ({u:.1}, {v:.1})")]
    EpipoleInImage {
        /// `reference` or `other`.
        camera: &'static str,
        /// Epipole column (px).
        u: f64,
        /// Epipole row (px).
        v: f64,
    },
    /// The two cameras look in opposite directions.
    #[error("the cameras look in opposite directions")]
    OppositeViews,
}
