//! The sizes a model may ask for, each with its reason (documented in
//! MODEL_FORMAT.md, "What is refused"). Beyond them a model is refused at
//! validation, naming the key — never a capacity-overflow panic or an
//! allocation abort part-way through a run.

/// Elements in one model: the assembly keeps about 7 kB of work space per
/// 2-node element (more for 3-node ones), so 200 000 elements take about
/// 1.5 GB before the sparse factorisation.
pub const MAX_ELEMENTS: (i64, &str) = (
    200_000,
    "elements in one model: about 7 kB of assembly memory each",
);
/// Newton iterations per step: a solve that has not converged in a thousand
/// iterations will not.
pub const MAX_ITERATIONS: (i64, &str) = (1_000, "Newton iterations per step");
/// Load steps of a static analysis (one record each).
pub const MAX_LOAD_STEPS: (i64, &str) = (1_000_000, "load steps, one stored record each");
/// Steps of a dynamic analysis, `t_end/dt`.
pub const MAX_TIME_STEPS: f64 = 1.0e7;
/// Consecutive step halvings: 2⁻⁵⁰ of a step is below any physical time scale.
pub const MAX_HALVINGS: (i64, &str) = (50, "step halvings: 2^-50 of a step");
/// Output stride.
pub const MAX_EVERY: (i64, &str) = (1_000_000_000, "steps between stored records");
/// Bytes of a model `name`, which becomes the file name `<name>.h5` (file
/// systems allow 255 bytes per name; studies add run suffixes).
pub const MAX_NAME_BYTES: usize = 200;

/// Most modes an analysis may ask for (each stored as nodes × 3 twice).
pub const MAX_MODES: (i64, &str) = (10_000, "modes, each stored for every node");
