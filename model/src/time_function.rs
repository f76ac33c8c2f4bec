//! Evaluation and checking of [`TimeFunction`]s.

use super::types::TimeFunction;

impl TimeFunction {
    /// A table function from `(t, value)` rows, checked with
    /// [`TimeFunction::validate`].
    pub fn table(rows: Vec<(f64, f64)>) -> Result<Self, String> {
        let f = TimeFunction::Table(rows);
        f.validate()?;
        Ok(f)
    }

    /// The value at time `t`: piecewise-linear between the table rows, constant
    /// (the first or last value) outside the table. An empty table, which
    /// [`TimeFunction::validate`] rejects, evaluates to 0.
    pub fn eval(&self, t: f64) -> f64 {
        match self {
            TimeFunction::Constant(c) => *c,
            TimeFunction::Expression(e) => e.eval::<f64>(t),
            TimeFunction::Table(rows) => {
                let (Some(first), Some(last)) = (rows.first(), rows.last()) else {
                    return 0.0;
                };
                if t <= first.0 {
                    return first.1;
                }
                if t >= last.0 {
                    return last.1;
                }
                // First row with time > t; 1 <= i < len because first.0 < t < last.0.
                let i = rows.partition_point(|&(ti, _)| ti <= t);
                let (t0, v0) = rows[i - 1];
                let (t1, v1) = rows[i];
                if t1 == t0 {
                    return v1;
                }
                let s = (t - t0) / (t1 - t0);
                v0 + s * (v1 - v0)
            }
        }
    }

    /// The value and its first and second derivatives at `t`: exact for an
    /// expression (second-order dual numbers), zero for a constant, and for
    /// a table its slope on the segment that starts at `t` (the right
    /// derivative; zero outside the table) and zero curvature.
    pub fn derivatives(&self, t: f64) -> (f64, f64, f64) {
        match self {
            TimeFunction::Constant(c) => (*c, 0.0, 0.0),
            TimeFunction::Expression(e) => e.derivatives(t),
            TimeFunction::Table(rows) => {
                let i = rows.partition_point(|&(ti, _)| ti <= t);
                let slope = if i == 0 || i == rows.len() {
                    0.0
                } else {
                    let ((t0, v0), (t1, v1)) = (rows[i - 1], rows[i]);
                    (v1 - v0) / (t1 - t0)
                };
                (self.eval(t), slope, 0.0)
            }
        }
    }

    /// Checks that the function is usable: every number finite; a table has at
    /// least one row and strictly increasing times; an expression is finite
    /// at t = 0. The error says what is wrong (rows are counted from 0).
    pub fn validate(&self) -> Result<(), String> {
        match self {
            TimeFunction::Expression(e) => {
                let v: f64 = e.eval(0.0);
                if v.is_finite() {
                    Ok(())
                } else {
                    Err(format!(
                        "the expression \"{}\" is {v:?} at t = 0; it must give a finite number",
                        e.text()
                    ))
                }
            }
            TimeFunction::Constant(c) => {
                if c.is_finite() {
                    Ok(())
                } else {
                    Err(format!("must be a finite number, found {c:?}"))
                }
            }
            TimeFunction::Table(rows) => {
                if rows.is_empty() {
                    return Err(
                        "the table is empty; give at least one [t, value] row, e.g. \
                         table = [[0.0, 0.0], [1.0, 1.0]]"
                            .to_string(),
                    );
                }
                for (k, &(t, v)) in rows.iter().enumerate() {
                    if !t.is_finite() || !v.is_finite() {
                        return Err(format!(
                            "row {k} must hold finite numbers, found [{t:?}, {v:?}]"
                        ));
                    }
                }
                for (k, pair) in rows.windows(2).enumerate() {
                    if pair[1].0 <= pair[0].0 {
                        return Err(format!(
                            "times must be strictly increasing, but row {} has t = {:?} \
                             after t = {:?} in row {k}",
                            k + 1,
                            pair[1].0,
                            pair[0].0
                        ));
                    }
                }
                Ok(())
            }
        }
    }
}
