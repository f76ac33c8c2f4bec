//! The benchmarks' reference data (`data/benchmarks/reference/*.csv`),
//! compiled in: comment lines start with `#`, then a header, then rows of
//! comma-separated values.

/// Mattiasson's published elastica table: `lambda, w, u`.
pub const ELASTICA: &str =
    include_str!("../../../data/benchmarks/reference/elastica_mattiasson.csv");
/// The Princeton beam's reference tip deflections: `force, beta_deg, y, z`.
pub const PRINCETON: &str =
    include_str!("../../../data/benchmarks/reference/princeton_reference.csv");
/// The four-bar authors' stored run: `t, x, y, z` of C.
pub const FOUR_BAR: &str = include_str!("../../../data/benchmarks/reference/four_bar_authors.csv");
/// The lateral buckling's independent run: `t, ux, uy, uz` at mid-span.
pub const LATERAL_BUCKLING: &str =
    include_str!("../../../data/benchmarks/reference/lateral_buckling_twin.csv");
/// The rotating shaft's independent run: `t, ux, uy, uz` at mid-span.
pub const ROTATING_SHAFT: &str =
    include_str!("../../../data/benchmarks/reference/rotating_shaft_twin.csv");
/// Lee's frame's exact limit loads: `point, load` (P L²/EI).
pub const LEE_FRAME: &str = include_str!("../../../data/benchmarks/reference/lee_frame_exact.csv");

/// The data rows of a reference file, as text fields.
pub fn fields(text: &str) -> Vec<Vec<&str>> {
    text.lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
        .skip(1)
        .map(|l| l.split(',').map(str::trim).collect())
        .collect()
}

/// The data rows of a reference file whose fields are all numbers (a field
/// that is not one reads as NaN, which the comparisons then show).
pub fn numbers(text: &str) -> Vec<Vec<f64>> {
    fields(text)
        .into_iter()
        .map(|r| r.iter().map(|f| f.parse().unwrap_or(f64::NAN)).collect())
        .collect()
}

/// Columns `c` of `rows`.
pub fn column(rows: &[Vec<f64>], c: usize) -> Vec<f64> {
    rows.iter().map(|r| r[c]).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_reference_file_has_rows_of_its_header_s_width() {
        for text in [
            ELASTICA,
            PRINCETON,
            FOUR_BAR,
            LATERAL_BUCKLING,
            ROTATING_SHAFT,
        ] {
            let rows = numbers(text);
            assert!(!rows.is_empty());
            assert!(rows
                .iter()
                .all(|r| r.len() == 4 - usize::from(text == ELASTICA)));
            assert!(rows.iter().flatten().all(|v| v.is_finite()));
        }
        assert_eq!(fields(LEE_FRAME).len(), 2);
    }
}
