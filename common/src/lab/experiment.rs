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
    UnpairedBvhStack,
    LocalBvhStack,
    SplitRayStack,
    StorageCounts,
    UniformCounts,
    NoContraction,
    FloatControls,
    Glslang,
    Quad,
    LoadClear,
    Rgba8,
    ComputeQueue,
    DynamicViewport,
    NagaAliasing,
    RobustAccess,
    WarpProbe,
}
