//! The chart holds one curve per value of b, labelled by it, each ending
//! (t = 0.5 s, ψ = π/2) at the ellipse's b semi-axis; its files are there.

use super::*;

#[test]
fn one_labelled_curve_per_run_ending_at_minus_b() {
    let out = tempfile::tempdir().unwrap();
    let chart = chart(out.path()).unwrap();
    let labels: Vec<&str> = chart.series.iter().map(|s| s.label.as_str()).collect();
    assert_eq!(labels, ["cam b = 0.02", "cam b = 0.03", "cam b = 0.04"]);
    for (s, b) in chart.series.iter().zip([0.02, 0.03, 0.04]) {
        assert_eq!(s.x.len(), 51);
        assert!((s.x[50] - 0.5).abs() <= 1e-12);
        assert!((s.y[0] + 0.02).abs() <= 1e-12, "starts at -a");
        assert!((s.y[50] + b).abs() <= 1e-12, "{}: {}", s.label, s.y[50]);
    }
    for ext in ["png", "svg", "tex", "csv"] {
        assert!(
            out.path().join(format!("follower.{ext}")).is_file(),
            "{ext}"
        );
    }
}
