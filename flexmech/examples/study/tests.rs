//! The study against the cam's geometry: the drive reaches ψ = π/2 at
//! t = 0.5 s, where the follower is at −b t_r, and r(ψ) grows monotonically
//! from a to b on the way (b ≥ a), so the deepest follower position is −b.

use super::*;

/// Positions of size 0.04 from a converged joint relation: round-off.
const ROUND_OFF: f64 = 1e-12;

#[test]
fn the_deepest_follower_position_is_minus_b_for_every_run() {
    let out = tempfile::tempdir().unwrap();
    let report = study(out.path()).unwrap();
    assert_eq!((report.runs, report.failed), (3, 0));
    let text = report.to_string();
    assert!(
        text.contains("summary.csv") && text.contains("runs"),
        "{text}"
    );
    let runs = report.study_runs().unwrap();
    let csv = std::fs::read_to_string(&report.csv).unwrap();
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let col = header.iter().position(|h| *h == "follower_x").unwrap();
    for (run, line) in runs.iter().zip(csv.lines().skip(1)) {
        let b: f64 = run.params[0].1.parse().unwrap();
        assert_eq!(
            run.label(),
            format!("cam b = {}, t_end = 0.5", run.params[0].1)
        );
        assert!(run.file.is_file(), "{}", run.file.display());
        let value: f64 = line.split(',').nth(col).unwrap().parse().unwrap();
        assert!(
            (value + b).abs() <= ROUND_OFF,
            "{line}: {value} against -{b}"
        );
    }
    assert!(report.dir.join("charts/follower_x.png").is_file());
}
