//! Decimation of long curves before they are drawn: the points are mapped to pixels, and
//! of each stretch of consecutive points that falls in one pixel column only the first,
//! the lowest, the highest and the last are kept. The drawn line then covers the same
//! pixels as the full curve (its min/max envelope per column), while the file holds at most
//! four points per column crossed. A curve that crosses the columns again and again (a
//! hysteresis loop of many cycles) is thinned further to [`MAX_VERTICES`].

/// Most vertices drawn for all the curves of one plot after decimation (a curve that
/// still has more is thinned by a stride; each vertex costs about 12 bytes of SVG).
pub(crate) const MAX_VERTICES: usize = 60_000;

/// Keep, of every stretch of consecutive points in one pixel column (`px` maps a point to
/// its pixel), the first, lowest, highest and last, in their order along the curve; then
/// drop points on the same pixel as the point kept before them.
pub(crate) fn envelope(
    run: &[(f64, f64)],
    px: impl Fn(&(f64, f64)) -> (i32, i32),
) -> Vec<(f64, f64)> {
    let mut out: Vec<(f64, f64)> = Vec::new();
    let mut last_px: Option<(i32, i32)> = None;
    let mut push = |p: (f64, f64), at: (i32, i32), out: &mut Vec<(f64, f64)>| {
        if last_px != Some(at) {
            out.push(p);
            last_px = Some(at);
        }
    };
    let mut start = 0;
    let pixels: Vec<(i32, i32)> = run.iter().map(&px).collect();
    while start < run.len() {
        let col = pixels[start].0;
        let mut end = start + 1;
        while end < run.len() && pixels[end].0 == col {
            end += 1;
        }
        // Pixel rows grow downwards: the highest point has the smallest row.
        let (mut lo, mut hi) = (start, start);
        for k in start..end {
            if pixels[k].1 > pixels[lo].1 {
                lo = k;
            }
            if pixels[k].1 < pixels[hi].1 {
                hi = k;
            }
        }
        let mut keep = [start, lo, hi, end - 1];
        keep.sort_unstable();
        for (i, &k) in keep.iter().enumerate() {
            if i == 0 || k != keep[i - 1] {
                push(run[k], pixels[k], &mut out);
            }
        }
        start = end;
    }
    out
}

/// Thin `runs` (already decimated) by one stride so that they hold at most `max`
/// vertices together; each run keeps its first and last point. Returns the stride (1: as
/// they were).
pub(crate) fn cap(runs: &mut [Vec<(f64, f64)>], max: usize) -> usize {
    let total: usize = runs.iter().map(Vec::len).sum();
    let stride = total.div_ceil(max.max(1)).max(1);
    if stride > 1 {
        for run in runs.iter_mut() {
            let last = run.last().copied();
            let mut thin: Vec<(f64, f64)> = run.iter().copied().step_by(stride).collect();
            if let Some(p) = last
                && thin.last() != Some(&p)
            {
                thin.push(p);
            }
            *run = thin;
        }
    }
    stride
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 1 unit = 1 pixel, rows downwards.
    fn px(p: &(f64, f64)) -> (i32, i32) {
        (p.0.floor() as i32, -(p.1.floor() as i32))
    }

    #[test]
    fn a_noisy_series_keeps_its_envelope_in_four_points_per_column() {
        // 10 columns of 1000 samples each, y swinging between -50 and +50.
        let run: Vec<(f64, f64)> =
            (0..10_000).map(|i| (i as f64 / 1000.0, 50.0 * ((i as f64) * 0.37).sin())).collect();
        let mut run = run;
        run[4321].1 = 80.0; // A one-sample spike survives.
        let d = envelope(&run, px);
        assert!(d.contains(&run[4321]));
        assert!(d.len() <= 40, "{} points", d.len());
        for c in 0..10 {
            let full: Vec<f64> =
                run.iter().filter(|p| p.0.floor() as i32 == c).map(|p| p.1).collect();
            let kept: Vec<f64> =
                d.iter().filter(|p| p.0.floor() as i32 == c).map(|p| p.1).collect();
            // Same highest and lowest pixel row as the full column.
            let max = |v: &[f64]| v.iter().copied().fold(f64::MIN, f64::max).floor();
            let min = |v: &[f64]| v.iter().copied().fold(f64::MAX, f64::min).floor();
            assert_eq!((max(&kept), min(&kept)), (max(&full), min(&full)), "column {c}");
            // The column is entered and left on the same pixels.
            assert_eq!(kept.first(), full.first());
            assert_eq!(kept.last().map(|y| y.floor()), full.last().map(|y| y.floor()));
        }
    }

    #[test]
    fn a_short_curve_is_kept_as_it_is_and_caps_thin_by_one_stride() {
        let run = vec![(0.0, 0.0), (1.0, 5.0), (2.0, 1.0)];
        assert_eq!(envelope(&run, px), run);
        let mut runs = vec![(0..100).map(|i| (i as f64, 0.0)).collect::<Vec<_>>()];
        assert_eq!(cap(&mut runs, 30), 4);
        assert_eq!(runs[0].len(), 26);
        assert_eq!(runs[0].last(), Some(&(99.0, 0.0)));
    }
}
