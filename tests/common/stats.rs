//! Pearson's chi-square goodness-of-fit test, with bins of small expectation pooled.

/// The p-value of a chi-square statistic with `dof` degrees of freedom, by the Wilson–Hilferty
/// cube-root normal approximation (accurate to a few parts in 1e3 for dof ≥ 10, plenty for a
/// pass/fail threshold of 1e-3).
pub fn chi_square_p_value(statistic: f64, dof: usize) -> f64 {
    let k = dof as f64;
    let z = ((statistic / k).powf(1.0 / 3.0) - (1.0 - 2.0 / (9.0 * k))) / (2.0 / (9.0 * k)).sqrt();
    0.5 * erfc(z / std::f64::consts::SQRT_2)
}

/// erfc by Numerical Recipes' Chebyshev fit (fractional error below 1.2e-7).
fn erfc(x: f64) -> f64 {
    let z = x.abs();
    let t = 1.0 / (1.0 + 0.5 * z);
    let poly = -z * z - 1.26551223
        + t * (1.00002368
            + t * (0.37409196
                + t * (0.09678418
                    + t * (-0.18628806
                        + t * (0.27886807
                            + t * (-1.13520398 + t * (1.48851587 + t * (-0.82215223 + t * 0.17087277))))))));
    let r = t * poly.exp();
    if x >= 0.0 {
        r
    } else {
        2.0 - r
    }
}

/// Outcome of a chi-square test.
#[derive(Debug)]
pub struct ChiSquare {
    pub statistic: f64,
    pub dof: usize,
    pub p_value: f64,
}

/// Compares observed counts with expected counts (same total), pooling bins expected to hold
/// fewer than 5 samples into one, as the test requires. A sample in a bin expected to be empty
/// is an outright failure: the sampler produced something its pdf says is impossible.
pub fn chi_square(observed: &[f64], expected: &[f64]) -> Result<ChiSquare, String> {
    let (mut statistic, mut dof) = (0.0, 0usize);
    let (mut pooled_observed, mut pooled_expected) = (0.0, 0.0);
    for (&o, &e) in observed.iter().zip(expected) {
        if e == 0.0 && o > 0.0 {
            return Err(format!("{o} samples fell in a bin whose expected count is 0"));
        }
        if e < 5.0 {
            pooled_observed += o;
            pooled_expected += e;
        } else {
            statistic += (o - e) * (o - e) / e;
            dof += 1;
        }
    }
    if pooled_expected >= 5.0 {
        statistic += (pooled_observed - pooled_expected).powi(2) / pooled_expected;
        dof += 1;
    } else if pooled_observed > 2.0 * pooled_expected + 10.0 {
        return Err(format!("{pooled_observed} samples in bins expected to hold {pooled_expected:.2}"));
    }
    let dof = dof.saturating_sub(1).max(1);
    Ok(ChiSquare { statistic, dof, p_value: chi_square_p_value(statistic, dof) })
}

#[cfg(test)]
mod tests {
    #[test]
    fn p_values_are_sane() {
        // The median of chi-square(k) is about k(1 − 2/9k)³.
        let p = super::chi_square_p_value(99.33, 100);
        assert!((p - 0.5).abs() < 0.01, "{p}");
        assert!(super::chi_square_p_value(150.0, 100) < 0.002);
    }
}
