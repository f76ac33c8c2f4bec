//! Clipping polylines to the plot rectangle (Liang–Barsky per segment):
//! curves stop at the frame instead of running over it and through the
//! notes around it.

/// A rectangle in pixels: left, top, right, bottom (`top < bottom`).
pub(crate) type Rect = (f64, f64, f64, f64);

/// The part of the segment `p0 → p1` inside `rect`, if any.
fn clip_segment(
    p0: (f64, f64),
    p1: (f64, f64),
    (l, t, r, b): Rect,
) -> Option<((f64, f64), (f64, f64))> {
    let (dx, dy) = (p1.0 - p0.0, p1.1 - p0.1);
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for (p, q) in [
        (-dx, p0.0 - l),
        (dx, r - p0.0),
        (-dy, p0.1 - t),
        (dy, b - p0.1),
    ] {
        if p == 0.0 {
            if q < 0.0 {
                return None;
            }
        } else {
            let u = q / p;
            if p < 0.0 {
                if u > t1 {
                    return None;
                }
                t0 = t0.max(u);
            } else {
                if u < t0 {
                    return None;
                }
                t1 = t1.min(u);
            }
        }
    }
    Some((
        (p0.0 + t0 * dx, p0.1 + t0 * dy),
        (p0.0 + t1 * dx, p0.1 + t1 * dy),
    ))
}

/// The pieces of a polyline inside `rect`, in order; a single point is kept
/// when it is inside.
pub(crate) fn clip_polyline(points: &[(f64, f64)], rect: Rect) -> Vec<Vec<(f64, f64)>> {
    let inside = |(x, y): (f64, f64)| x >= rect.0 && x <= rect.2 && y >= rect.1 && y <= rect.3;
    if points.len() == 1 {
        return if inside(points[0]) {
            vec![points.to_vec()]
        } else {
            Vec::new()
        };
    }
    let mut pieces = Vec::new();
    let mut current: Vec<(f64, f64)> = Vec::new();
    for w in points.windows(2) {
        match clip_segment(w[0], w[1], rect) {
            Some((a, b)) => {
                if current.last() != Some(&a) {
                    if current.len() > 1 {
                        pieces.push(std::mem::take(&mut current));
                    }
                    current = vec![a];
                }
                current.push(b);
                if b != w[1] {
                    pieces.push(std::mem::take(&mut current));
                }
            }
            None => {
                if current.len() > 1 {
                    pieces.push(std::mem::take(&mut current));
                }
                current.clear();
            }
        }
    }
    if current.len() > 1 {
        pieces.push(current);
    }
    pieces
}

#[cfg(test)]
mod tests {
    use super::*;

    const FRAME: Rect = (0.0, 0.0, 10.0, 10.0);

    #[test]
    fn a_line_through_the_frame_is_cut_at_its_edges() {
        let p = clip_polyline(&[(-5.0, 5.0), (5.0, 5.0), (15.0, 5.0)], FRAME);
        assert_eq!(p, vec![vec![(0.0, 5.0), (5.0, 5.0), (10.0, 5.0)]]);
    }

    #[test]
    fn leaving_and_coming_back_gives_two_pieces() {
        let p = clip_polyline(&[(2.0, 2.0), (2.0, 20.0), (8.0, 20.0), (8.0, 2.0)], FRAME);
        assert_eq!(
            p,
            vec![vec![(2.0, 2.0), (2.0, 10.0)], vec![(8.0, 10.0), (8.0, 2.0)]]
        );
    }

    #[test]
    fn outside_points_vanish_and_inside_ones_stay() {
        assert!(clip_polyline(&[(-1.0, -1.0), (-2.0, 20.0)], FRAME).is_empty());
        assert_eq!(clip_polyline(&[(3.0, 3.0)], FRAME), vec![vec![(3.0, 3.0)]]);
        assert!(clip_polyline(&[(30.0, 3.0)], FRAME).is_empty());
    }
}
