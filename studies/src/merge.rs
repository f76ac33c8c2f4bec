//! `--merge`: the shard summaries of a study into the summary an unsharded
//! run writes.

use std::path::{Path, PathBuf};

use super::execute::{plans, study_dir, write_summary};
use super::shard::Shard;
use super::spec::StudySpec;
use super::summary::{self, Cell, Summary};
use super::sweep::run_index;
use super::{StudyError, StudyReport};

/// Why the shard summaries could not be merged; each names the directory or
/// file and the fix.
#[derive(Debug, thiserror::Error)]
pub enum MergeError {
    /// The study directory cannot be listed.
    #[error("{}: cannot list the study directory: {source}; run the shards first", .dir.display())]
    List {
        /// The directory.
        dir: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// No shard summary at all.
    #[error(
        "{}: no summary-shard-K-of-N.csv files; run the shards first \
         (flexmech study STUDY.toml --shard K/N, or as a Slurm array)",
        .dir.display()
    )]
    NoShards {
        /// The directory.
        dir: PathBuf,
    },
    /// Shard summaries of different shard counts N.
    #[error(
        "{}: shard summaries for different shard counts N ({}); remove the stale files of the \
         earlier split and merge again",
        .dir.display(),
        .files.join(", ")
    )]
    MixedCounts {
        /// The directory.
        dir: PathBuf,
        /// The shard files found.
        files: Vec<String>,
    },
    /// Some shards of 1..=N have no summary.
    #[error(
        "{}: missing {}; run {} and merge again",
        .dir.display(),
        .missing.iter().map(|s| format!("{}.csv", s.summary_stem())).collect::<Vec<_>>().join(", "),
        .missing.iter().map(|s| format!("--shard {s}")).collect::<Vec<_>>().join(", ")
    )]
    MissingShards {
        /// The directory.
        dir: PathBuf,
        /// The shards without a summary.
        missing: Vec<Shard>,
    },
    /// A run id that is not one of the study's runs.
    #[error(
        "{}: run id \"{run}\" is not a run of this study ({total} runs, run ids up to {last}); \
         the shard was written for another grid: run it again",
        .file.display()
    )]
    UnknownRun {
        /// The shard file.
        file: PathBuf,
        /// The run id.
        run: String,
        /// How many runs the study has.
        total: usize,
        /// The last run id of the study.
        last: String,
    },
    /// A run appears in two shard summaries (or twice in one).
    #[error(
        "run {run} appears twice, in {} and {}; remove the stale shard file and merge again",
        .first.display(),
        .second.display()
    )]
    DuplicateRun {
        /// The run id.
        run: String,
        /// Where it appeared first.
        first: PathBuf,
        /// Where it appeared again.
        second: PathBuf,
    },
    /// Runs that no shard summary holds.
    #[error(
        "{}: no shard summary holds run(s) {}; run the shard(s) that own them again and merge",
        .dir.display(),
        .runs.join(", ")
    )]
    MissingRuns {
        /// The directory.
        dir: PathBuf,
        /// The missing run ids (at most 20 listed).
        runs: Vec<String>,
    },
    /// A row's swept values are not those of the study's run.
    #[error(
        "{}: run {run} has {column} = {found} but the study file gives {expected}; the shard \
         was written for another grid: run it again",
        .file.display()
    )]
    ValueMismatch {
        /// The shard file.
        file: PathBuf,
        /// The run id.
        run: String,
        /// The grid key.
        column: String,
        /// The value in the shard file.
        found: String,
        /// The value of the study file.
        expected: String,
    },
}

/// The shard summaries in `dir`, by shard, sorted by K.
fn shard_files(dir: &Path) -> Result<Vec<(Shard, PathBuf)>, MergeError> {
    let entries = std::fs::read_dir(dir).map_err(|source| MergeError::List {
        dir: dir.to_path_buf(),
        source,
    })?;
    let mut found = Vec::new();
    for entry in entries {
        let entry = entry.map_err(|source| MergeError::List {
            dir: dir.to_path_buf(),
            source,
        })?;
        let name = entry.file_name();
        if let Some(shard) = name.to_str().and_then(Shard::from_summary_file_name) {
            found.push((shard, entry.path()));
        }
    }
    found.sort_by_key(|(s, _)| (s.n, s.k));
    Ok(found)
}

/// Reads every `summary-shard-K-of-N.csv` of `spec` below `out`, checks that
/// shards 1..=N of one N are all there and that together they hold every run
/// exactly once with the study's values, and writes `summary.csv`,
/// `summary.h5` and the charts as an unsharded run would (rows in run
/// order).
pub fn merge_study(spec: &StudySpec, out: &Path) -> Result<StudyReport, StudyError> {
    let dir = study_dir(spec, out);
    let files = shard_files(&dir)?;
    let Some(&(first, _)) = files.first() else {
        return Err(MergeError::NoShards { dir }.into());
    };
    let n = first.n;
    if files.iter().any(|(s, _)| s.n != n) {
        let names = files
            .iter()
            .map(|(s, _)| format!("{}.csv", s.summary_stem()))
            .collect();
        return Err(MergeError::MixedCounts { dir, files: names }.into());
    }
    let missing: Vec<Shard> = (1..=n)
        .filter(|k| !files.iter().any(|(s, _)| s.k == *k))
        .map(|k| Shard { k, n })
        .collect();
    if !missing.is_empty() {
        return Err(MergeError::MissingShards { dir, missing }.into());
    }

    let all = plans(spec);
    let cols = summary::columns(spec);
    let mut slots: Vec<Option<(Vec<Cell>, PathBuf)>> = vec![None; all.len()];
    for (_, file) in &files {
        let table = Summary::read_csv(file, &cols)?;
        for row in table.rows {
            let id = row[0].csv_text();
            let index = run_index(&id).filter(|&i| i < all.len() && all[i].id == id);
            let Some(index) = index else {
                return Err(MergeError::UnknownRun {
                    file: file.clone(),
                    run: id,
                    total: all.len(),
                    last: all.last().map(|p| p.id.clone()).unwrap_or_default(),
                }
                .into());
            };
            for (g, (key, value)) in spec.grid.iter().zip(&all[index].values).enumerate() {
                let expected = summary::value_cell(value, cols[1 + g].kind).csv_text();
                let found = row[1 + g].csv_text();
                if found != expected {
                    return Err(MergeError::ValueMismatch {
                        file: file.clone(),
                        run: id,
                        column: key.key.clone(),
                        found,
                        expected,
                    }
                    .into());
                }
            }
            if let Some((_, first)) = &slots[index] {
                return Err(MergeError::DuplicateRun {
                    run: id,
                    first: first.clone(),
                    second: file.clone(),
                }
                .into());
            }
            slots[index] = Some((row, file.clone()));
        }
    }
    let missing_runs: Vec<String> = slots
        .iter()
        .zip(&all)
        .filter(|(s, _)| s.is_none())
        .map(|(_, p)| p.id.clone())
        .take(20)
        .collect();
    if !missing_runs.is_empty() {
        return Err(MergeError::MissingRuns {
            dir,
            runs: missing_runs,
        }
        .into());
    }
    let rows = slots.into_iter().flatten().map(|(row, _)| row).collect();
    let table = Summary {
        columns: cols,
        rows,
    };
    write_summary(spec, &dir, &table, None)
}
