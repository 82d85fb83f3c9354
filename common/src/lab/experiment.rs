//! The experiments' names: `--experiment NAME`, as committed CSVs, variant
//! labels and investigation scripts spell them. What each one does lives in
//! the registry (`lab::REGISTRY`); this file only names them, so that the
//! shared options can parse them without depending on the laboratory.

/// One experiment of the laboratory (see `lab::REGISTRY` for what each does).
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, clap::ValueEnum, serde::Serialize,
)]
#[serde(rename_all = "kebab-case")]
pub enum Experiment {
    NagaZeroInit,
    NagaLoopBounding,
    NoLoopBounding,
    SharedBvhStack,
    LocalBvhStack,
    SplitRayStack,
    UnpairedBvhStack,
    CappedBvhStack,
    FirstOfEquals,
    GreedyCollapse,
    WalkThenShade,
    StorageNodes,
    UniformCounts,
    NoContraction,
    FloatControls,
    Glslang,
    NagaAliasing,
    WarpProbe,
    TimedBarrier,
    BackToBack,
    RowOrder,
    Ulp,
}

/// One f32 operation the arithmetic probe (`--experiment ulp --ulp-op OP`)
/// measures: what the tracer computes with, plus two controls (`add`, `mul`)
/// and `bits`, which moves the input's bits through unchanged to check the
/// transport. shaders/lab/ulp.glsl implements each under `ULP_OP_<NAME>`
/// (upper snake case of the name); `twinray ulp` recomputes the inputs and
/// the f64 references.
#[derive(
    Debug,
    Clone,
    Copy,
    PartialEq,
    Eq,
    PartialOrd,
    Ord,
    Hash,
    clap::ValueEnum,
    serde::Serialize,
    serde::Deserialize,
)]
#[serde(rename_all = "kebab-case")]
pub enum UlpOp {
    Bits,
    Add,
    Mul,
    Div,
    Sqrt,
    Inversesqrt,
    Pow,
    Fma,
    Min,
    Max,
    Clamp,
    Dot,
    Length,
    Normalize,
    Cross,
    Reflect,
    Refract,
}

impl UlpOp {
    /// The define that selects it in shaders/lab/ulp.glsl.
    pub fn define(self) -> String {
        format!("ULP_OP_{:?}", self).to_uppercase()
    }
}
