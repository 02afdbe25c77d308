//! [`Distribution`] (count, mean, percentiles) and [`Histogram`]: how the report
//! summarises a list of values. Empty lists give zeros, never NaN.

/// Summary of a list of values: count, mean, extremes and percentiles (linear
/// interpolation between order statistics, as NumPy's default). All zero for no values.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Distribution {
    /// Number of values.
    pub count: usize,
    /// Sum of the values.
    pub total: f64,
    /// Mean.
    pub mean: f64,
    /// Smallest value.
    pub min: f64,
    /// 10th percentile.
    pub p10: f64,
    /// 25th percentile.
    pub p25: f64,
    /// Median.
    pub median: f64,
    /// 75th percentile.
    pub p75: f64,
    /// 90th percentile.
    pub p90: f64,
    /// Largest value.
    pub max: f64,
}

impl Distribution {
    /// Summarises `values`; non-finite values are left out.
    pub fn of(values: impl IntoIterator<Item = f64>) -> Distribution {
        let mut v: Vec<f64> = values.into_iter().filter(|x| x.is_finite()).collect();
        if v.is_empty() {
            return Distribution::default();
        }
        v.sort_unstable_by(f64::total_cmp);
        let total: f64 = v.iter().sum();
        Distribution {
            count: v.len(),
            total,
            mean: total / v.len() as f64,
            min: v[0],
            p10: percentile_sorted(&v, 0.10),
            p25: percentile_sorted(&v, 0.25),
            median: percentile_sorted(&v, 0.50),
            p75: percentile_sorted(&v, 0.75),
            p90: percentile_sorted(&v, 0.90),
            max: v[v.len() - 1],
        }
    }
}

/// The `q`-quantile (`q` in [0, 1]) of sorted finite values by linear interpolation;
/// 0 for none.
pub fn percentile_sorted(sorted: &[f64], q: f64) -> f64 {
    match sorted.len() {
        0 => 0.0,
        1 => sorted[0],
        n => {
            let pos = q.clamp(0.0, 1.0) * (n - 1) as f64;
            let lo = pos.floor() as usize;
            let hi = (lo + 1).min(n - 1);
            let f = pos - lo as f64;
            sorted[lo] + (sorted[hi] - sorted[lo]) * f
        }
    }
}

/// Counts of values in consecutive bins `[edges[i], edges[i+1])`; the last bin also
/// holds values equal to its upper edge. With `open_top`, one more bin holds everything
/// at or above the last edge.
#[derive(Debug, Clone, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Histogram {
    /// Bin edges, ascending (finite).
    pub edges: Vec<f64>,
    /// Whether the last bin is `[last edge, ∞)`.
    pub open_top: bool,
    /// Values per bin: `edges.len() - 1` bins, plus one when `open_top`.
    pub counts: Vec<usize>,
}

impl Histogram {
    /// Counts `values` in the bins of `edges` (ascending, finite); values outside every
    /// bin or non-finite are not counted.
    pub fn of(edges: &[f64], open_top: bool, values: impl IntoIterator<Item = f64>) -> Histogram {
        let closed = edges.len().saturating_sub(1);
        let bins = closed + usize::from(open_top && !edges.is_empty());
        let mut counts = vec![0; bins];
        for v in values {
            if !v.is_finite() || bins == 0 {
                continue;
            }
            // The number of edges at or below v: v's bin plus one.
            let i = edges.partition_point(|e| *e <= v);
            if i == 0 {
                continue;
            }
            if i <= closed || (open_top && i - 1 < bins) {
                counts[i - 1] += 1;
            } else if closed > 0 && v == edges[closed] {
                counts[closed - 1] += 1;
            }
        }
        Histogram {
            edges: edges.to_vec(),
            open_top,
            counts,
        }
    }

    /// Values counted.
    pub fn total(&self) -> usize {
        self.counts.iter().sum()
    }
}

/// `part / whole`, or 0 when `whole` is 0 (or the ratio is not finite). Never −0 (an
/// empty `f64` sum is −0 in Rust, which would print as "-0.0").
pub fn ratio(part: f64, whole: f64) -> f64 {
    let r = part / whole;
    if whole != 0.0 && r.is_finite() {
        r + 0.0
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percentiles_interpolate() {
        let d = Distribution::of([4.0, 1.0, 3.0, 2.0]);
        assert_eq!(d.count, 4);
        assert_eq!(d.median, 2.5);
        assert_eq!(d.min, 1.0);
        assert_eq!(d.max, 4.0);
        assert_eq!(d.mean, 2.5);
        assert_eq!(d.p25, 1.75);
        assert_eq!(Distribution::of([7.0]).p90, 7.0);
        assert_eq!(Distribution::of([]), Distribution::default());
        assert_eq!(Distribution::of([f64::NAN]).count, 0);
    }

    #[test]
    fn histogram_bins() {
        let h = Histogram::of(
            &[0.0, 1.0, 2.0],
            false,
            [0.0, 0.5, 1.0, 2.0, 3.0, -1.0, f64::NAN],
        );
        assert_eq!(h.counts, vec![2, 2]);
        let open = Histogram::of(&[0.0, 10.0], true, [5.0, 10.0, 50.0, 5000.0, -1.0]);
        assert_eq!(open.counts, vec![1, 3]);
        assert_eq!(Histogram::of(&[], true, [1.0]).total(), 0);
        assert_eq!(Histogram::of(&[3.0], true, [1.0, 3.0, 4.0]).counts, vec![2]);
        assert_eq!(ratio(1.0, 0.0), 0.0);
        let empty: f64 = std::iter::empty::<f64>().sum();
        assert!(ratio(empty, 3.0).is_sign_positive());
    }
}
