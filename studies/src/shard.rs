//! Splitting a study's runs over several processes: `--shard K/N` and its
//! fallback, the environment of a Slurm job array.
//!
//! Shard `K` of `N` (1 ≤ K ≤ N) takes the runs whose 0-based index `i`
//! satisfies `i % N == K − 1`, so shards stay balanced whatever the grid.
//!
//! Without `--shard`, a task of a Slurm job array is shard
//! `K = (SLURM_ARRAY_TASK_ID − SLURM_ARRAY_TASK_MIN) / SLURM_ARRAY_TASK_STEP + 1`
//! of `N = SLURM_ARRAY_TASK_COUNT`; `SLURM_ARRAY_TASK_MIN` defaults to 0 and
//! `SLURM_ARRAY_TASK_STEP` to 1 when unset. So `#SBATCH --array=0-3` and
//! `--array=1-4` both give shards 1/4 … 4/4. An array with gaps
//! (`--array=0,2,5`) cannot be mapped and is an error: pass `--shard K/N`.

use std::fmt;
use std::str::FromStr;

/// One shard of a study: the `k`-th (1-based) of `n`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Shard {
    /// Which shard, 1 ≤ k ≤ n.
    pub k: usize,
    /// How many shards.
    pub n: usize,
}

/// Why a shard could not be determined; the message says what was found and
/// what is expected.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ShardError {
    /// `--shard` is not of the form `K/N` with whole numbers.
    #[error(
        "--shard \"{text}\": expected K/N with whole numbers, e.g. --shard 2/4 for the second of four shards"
    )]
    Syntax {
        /// The text given.
        text: String,
    },
    /// `N` is zero or `K` is outside `1..=N`.
    #[error("--shard {k}/{n}: K must be between 1 and N (and N at least 1), e.g. --shard 1/{}", (*.n).max(1))]
    OutOfRange {
        /// K as given.
        k: usize,
        /// N as given.
        n: usize,
    },
    /// A Slurm variable is not a whole number.
    #[error("environment variable {var}=\"{value}\" is not a whole number; fix the job script or pass --shard K/N")]
    SlurmNotNumber {
        /// The variable.
        var: &'static str,
        /// Its value.
        value: String,
    },
    /// Only one of `SLURM_ARRAY_TASK_ID` and `SLURM_ARRAY_TASK_COUNT` is set.
    #[error(
        "{set} is set but {unset} is not, so the shard cannot be derived from the Slurm job \
         array; pass --shard K/N"
    )]
    SlurmIncomplete {
        /// The variable that is set.
        set: &'static str,
        /// The variable that is missing.
        unset: &'static str,
    },
    /// The task id does not map onto `1..=COUNT`.
    #[error(
        "Slurm array task {id} (SLURM_ARRAY_TASK_MIN={min}, SLURM_ARRAY_TASK_STEP={step}, \
         SLURM_ARRAY_TASK_COUNT={count}) does not map to a shard 1..={count}; use a contiguous \
         array such as --array=0-{last} or pass --shard K/N",
        last = (*.count).max(1) - 1
    )]
    SlurmOutOfRange {
        /// SLURM_ARRAY_TASK_ID.
        id: usize,
        /// SLURM_ARRAY_TASK_MIN (0 if unset).
        min: usize,
        /// SLURM_ARRAY_TASK_STEP (1 if unset).
        step: usize,
        /// SLURM_ARRAY_TASK_COUNT.
        count: usize,
    },
}

impl Shard {
    /// Shard `k` of `n`, checked: `1 ≤ k ≤ n`.
    pub fn new(k: usize, n: usize) -> Result<Self, ShardError> {
        if n == 0 || k == 0 || k > n {
            return Err(ShardError::OutOfRange { k, n });
        }
        Ok(Self { k, n })
    }

    /// Whether the run with 0-based `index` belongs to this shard.
    pub fn includes(&self, index: usize) -> bool {
        index % self.n == self.k - 1
    }

    /// File stem of this shard's summary: `summary-shard-K-of-N`.
    pub fn summary_stem(&self) -> String {
        format!("summary-shard-{}-of-{}", self.k, self.n)
    }

    /// The shard whose summary CSV is named `file_name`
    /// (`summary-shard-K-of-N.csv`), if it is one.
    pub fn from_summary_file_name(file_name: &str) -> Option<Self> {
        let rest = file_name
            .strip_prefix("summary-shard-")?
            .strip_suffix(".csv")?;
        let (k, n) = rest.split_once("-of-")?;
        let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
        if !digits(k) || !digits(n) {
            return None;
        }
        Shard::new(k.parse().ok()?, n.parse().ok()?).ok()
    }
}

impl fmt::Display for Shard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.k, self.n)
    }
}

impl FromStr for Shard {
    type Err = ShardError;

    /// Parses `K/N` (surrounding spaces allowed).
    fn from_str(text: &str) -> Result<Self, ShardError> {
        let syntax = || ShardError::Syntax {
            text: text.to_owned(),
        };
        let (k, n) = text.trim().split_once('/').ok_or_else(syntax)?;
        let number = |s: &str| {
            let s = s.trim();
            if s.is_empty() || !s.bytes().all(|b| b.is_ascii_digit()) {
                return Err(syntax());
            }
            s.parse::<usize>().map_err(|_| syntax())
        };
        Shard::new(number(k)?, number(n)?)
    }
}

/// The Slurm job-array variables that select a shard, as strings (`None`
/// when unset). Build it with [`SlurmArray::from_env`], or directly (tests).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct SlurmArray {
    /// `SLURM_ARRAY_TASK_ID`.
    pub task_id: Option<String>,
    /// `SLURM_ARRAY_TASK_COUNT`.
    pub task_count: Option<String>,
    /// `SLURM_ARRAY_TASK_MIN` (0 when unset).
    pub task_min: Option<String>,
    /// `SLURM_ARRAY_TASK_STEP` (1 when unset).
    pub task_step: Option<String>,
}

impl SlurmArray {
    /// Reads the variables from the process environment (an unset or
    /// non-Unicode variable counts as unset).
    pub fn from_env() -> Self {
        let var = |name| std::env::var(name).ok();
        Self {
            task_id: var("SLURM_ARRAY_TASK_ID"),
            task_count: var("SLURM_ARRAY_TASK_COUNT"),
            task_min: var("SLURM_ARRAY_TASK_MIN"),
            task_step: var("SLURM_ARRAY_TASK_STEP"),
        }
    }

    /// The shard of this array task; `None` when neither
    /// `SLURM_ARRAY_TASK_ID` nor `SLURM_ARRAY_TASK_COUNT` is set (not an
    /// array job).
    pub fn shard(&self) -> Result<Option<Shard>, ShardError> {
        fn number(var: &'static str, value: &str) -> Result<usize, ShardError> {
            value
                .trim()
                .parse::<usize>()
                .map_err(|_| ShardError::SlurmNotNumber {
                    var,
                    value: value.to_owned(),
                })
        }
        const ID: &str = "SLURM_ARRAY_TASK_ID";
        const COUNT: &str = "SLURM_ARRAY_TASK_COUNT";
        let (id, count) = match (&self.task_id, &self.task_count) {
            (None, None) => return Ok(None),
            (Some(_), None) => {
                return Err(ShardError::SlurmIncomplete {
                    set: ID,
                    unset: COUNT,
                })
            }
            (None, Some(_)) => {
                return Err(ShardError::SlurmIncomplete {
                    set: COUNT,
                    unset: ID,
                })
            }
            (Some(id), Some(count)) => (number(ID, id)?, number(COUNT, count)?),
        };
        let min = match &self.task_min {
            Some(v) => number("SLURM_ARRAY_TASK_MIN", v)?,
            None => 0,
        };
        let step = match &self.task_step {
            Some(v) => number("SLURM_ARRAY_TASK_STEP", v)?,
            None => 1,
        };
        let out_of_range = ShardError::SlurmOutOfRange {
            id,
            min,
            step,
            count,
        };
        if id < min || step == 0 || (id - min) % step != 0 {
            return Err(out_of_range);
        }
        // (id − min)/step + 1 overflows for an id near 2⁶⁴ − 1: out of range too.
        let Some(k) = ((id - min) / step).checked_add(1) else {
            return Err(out_of_range);
        };
        if count == 0 || k > count {
            return Err(out_of_range);
        }
        Ok(Some(Shard { k, n: count }))
    }
}

/// The shard to run: `flag` (the `--shard` text) when given, else the one of
/// the Slurm job array `slurm` describes, else `None` (every run).
pub fn select_shard(flag: Option<&str>, slurm: &SlurmArray) -> Result<Option<Shard>, ShardError> {
    match flag {
        Some(text) => text.parse().map(Some),
        None => slurm.shard(),
    }
}
