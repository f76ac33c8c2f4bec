//! Polylines as pixels and dash patterns (on, off, … in pixels, with
//! dash-dot patterns plotters' own dashed series does not draw), keeping the
//! pattern's phase across vertices.

pub(super) fn pixels(points: &[(f64, f64)]) -> Vec<(i32, i32)> {
    let mut out: Vec<(i32, i32)> = Vec::with_capacity(points.len());
    for &(x, y) in points {
        let p = (x.round() as i32, y.round() as i32);
        if out.last() != Some(&p) {
            out.push(p);
        }
    }
    if out.len() == 1 {
        out.push(out[0]);
    }
    out
}

/// Cuts a polyline into the "on" pieces of a dash pattern (pixel lengths,
/// alternating on and off), keeping the pattern's phase across vertices.
pub(super) fn dashed(points: &[(f64, f64)], pattern: &[f64]) -> Vec<Vec<(f64, f64)>> {
    if pattern.is_empty() || points.len() < 2 {
        return vec![points.to_vec()];
    }
    let mut pieces = Vec::new();
    let mut current = vec![points[0]];
    let mut index = 0;
    let mut left = pattern[0];
    for w in points.windows(2) {
        let (mut a, b) = (w[0], w[1]);
        let mut d = (b.0 - a.0).hypot(b.1 - a.1);
        while d > left {
            let f = left / d;
            let p = (a.0 + f * (b.0 - a.0), a.1 + f * (b.1 - a.1));
            if index % 2 == 0 {
                current.push(p);
                pieces.push(std::mem::take(&mut current));
            } else {
                current = vec![p];
            }
            a = p;
            d -= left;
            index = (index + 1) % pattern.len();
            left = pattern[index];
        }
        left -= d;
        if index % 2 == 0 {
            current.push(b);
        }
    }
    if index % 2 == 0 && current.len() > 1 {
        pieces.push(current);
    }
    pieces
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dashes_keep_their_phase() {
        let line = [(0.0, 0.0), (5.0, 0.0), (30.0, 0.0)];
        let pieces = dashed(&line, &[10.0, 5.0]);
        let spans: Vec<(f64, f64)> = pieces
            .iter()
            .map(|p| (p[0].0, p.last().unwrap().0))
            .collect();
        assert_eq!(spans, [(0.0, 10.0), (15.0, 25.0)]);
    }
}
