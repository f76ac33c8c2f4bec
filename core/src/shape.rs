//! Lagrange shape functions on `ξ ∈ [−1, 1]` with equally spaced nodes, and the
//! reduced Gauss rules of the beam elements.

/// Values `Iᵢ(ξ)` and derivatives `dIᵢ/dξ` of the `n`-node Lagrange polynomials
/// (`n` = 2 or 3; nodes at ξ = −1, (0,) 1), written into the first `n` slots.
pub fn lagrange(n: usize, xi: f64) -> ([f64; 3], [f64; 3]) {
    match n {
        2 => ([0.5 * (1.0 - xi), 0.5 * (1.0 + xi), 0.0], [-0.5, 0.5, 0.0]),
        3 => (
            [0.5 * xi * (xi - 1.0), 1.0 - xi * xi, 0.5 * xi * (xi + 1.0)],
            [xi - 0.5, -2.0 * xi, xi + 0.5],
        ),
        _ => unreachable!("beam elements have 2 or 3 nodes"),
    }
}

/// Reduced (n − 1 point) Gauss–Legendre rule `(ξ_g, w_g)` for an `n`-node element.
pub fn reduced_gauss(n: usize) -> &'static [(f64, f64)] {
    const ONE: [(f64, f64); 1] = [(0.0, 2.0)];
    // ±1/√3
    const TWO: [(f64, f64); 2] = [
        (-0.577_350_269_189_625_8, 1.0),
        (0.577_350_269_189_625_8, 1.0),
    ];
    match n {
        2 => &ONE,
        3 => &TWO,
        _ => unreachable!("beam elements have 2 or 3 nodes"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn partition_of_unity_and_interpolation() {
        for n in [2, 3] {
            for k in 0..=20 {
                let xi = -1.0 + 0.1 * k as f64;
                let (v, d) = lagrange(n, xi);
                assert!((v[..n].iter().sum::<f64>() - 1.0).abs() < 1e-15);
                assert!(d[..n].iter().sum::<f64>().abs() < 1e-15);
                // Linear functions are reproduced: Σ Iᵢ ξᵢ = ξ, Σ Iᵢ' ξᵢ = 1.
                let nodes: Vec<f64> = (0..n)
                    .map(|i| -1.0 + 2.0 * i as f64 / (n - 1) as f64)
                    .collect();
                let lin: f64 = (0..n).map(|i| v[i] * nodes[i]).sum();
                let dlin: f64 = (0..n).map(|i| d[i] * nodes[i]).sum();
                assert!((lin - xi).abs() < 1e-15 && (dlin - 1.0).abs() < 1e-15);
            }
        }
    }

    #[test]
    fn gauss_rules_integrate_their_degree() {
        // n−1 points integrate polynomials of degree 2n−3 exactly.
        for (n, deg) in [(2, 1), (3, 3)] {
            for p in 0..=deg {
                let exact = if p % 2 == 1 {
                    0.0
                } else {
                    2.0 / (p as f64 + 1.0)
                };
                let q: f64 = reduced_gauss(n).iter().map(|(x, w)| w * x.powi(p)).sum();
                assert!((q - exact).abs() < 1e-15, "n={n} p={p}");
            }
        }
    }
}
