//! Plots of large data stay small: long series are decimated to the plot's pixels, dense
//! fitted curves are thinned, and heatmaps of large grids are one embedded image.

use std::path::PathBuf;

use hd_plot::{Series, fit_plot, heatmap, line_plot};

/// The bound on any plot file [bytes].
const MAX_BYTES: u64 = 2_000_000;

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("hd-plot-large-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn size(path: &std::path::Path) -> u64 {
    std::fs::metadata(path).unwrap().len()
}

#[test]
fn a_four_million_sample_series_keeps_its_envelope_in_a_small_svg() {
    let dir = scratch("long");
    let n = 4_000_000;
    let t: Vec<f64> = (0..n).map(|i| i as f64 * 1e-4).collect();
    // A 50 Hz ripple on a slow swing, with one spike.
    let mut y: Vec<f64> = t
        .iter()
        .map(|t| (0.05 * t).sin() + 0.2 * (2.0 * std::f64::consts::PI * 50.0 * t).sin())
        .collect();
    y[2_345_678] = 7.5;
    let path = dir.join("long.svg");
    line_plot(&path, "long run", "t [s]", "θ [rad]", &[Series::new("θ", t, y)], false).unwrap();
    assert!(size(&path) < MAX_BYTES, "{} bytes", size(&path));
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn a_two_million_sample_hysteresis_fit_stays_under_two_megabytes() {
    let dir = scratch("loop");
    let n = 2_000_000;
    // 200 cycles of a loop: x = sin, y = sin shifted (an ellipse), with noise on measured.
    let phase: Vec<f64> =
        (0..n).map(|i| i as f64 * 2.0 * std::f64::consts::PI * 200.0 / n as f64).collect();
    let x: Vec<f64> = phase.iter().map(|p| p.sin()).collect();
    let fitted: Vec<f64> = phase.iter().map(|p| (p + 0.4).sin()).collect();
    let measured: Vec<f64> =
        fitted.iter().enumerate().map(|(i, f)| f + 0.01 * ((i as f64) * 1.7).sin()).collect();
    let path = dir.join("loop.svg");
    fit_plot(
        &path,
        "loop",
        "θ [rad]",
        "τ [N·m]",
        &Series::new("measured", x.clone(), measured),
        &Series::new("fitted", x, fitted),
    )
    .unwrap();
    assert!(size(&path) < MAX_BYTES, "{} bytes", size(&path));
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn a_thousand_by_thousand_heatmap_is_an_embedded_image() {
    let dir = scratch("heat");
    let n = 1000;
    let xs: Vec<f64> = (0..n).map(|i| 1e3 * 1.01f64.powi(i)).collect();
    let ys: Vec<f64> = (0..n).map(|i| i as f64).collect();
    let mut values: Vec<f64> =
        (0..n * n).map(|k| f64::from(k % n).sqrt() + f64::from(k / n)).collect();
    values[17] = f64::NAN;
    for ext in ["svg", "png"] {
        let path = dir.join(format!("heat.{ext}"));
        heatmap(
            &path,
            "grid",
            "K [N·m/rad]",
            "J [kg·m²]",
            &xs,
            &ys,
            &values,
            "thz_amp [rad]",
            true,
            false,
        )
        .unwrap();
        assert!(size(&path) < MAX_BYTES, "{ext}: {} bytes", size(&path));
        if ext == "svg" {
            let text = std::fs::read_to_string(&path).unwrap();
            assert!(text.contains("<image"), "the cells are one image");
            assert!(text.matches("<rect").count() < 1000, "not one rectangle per cell");
        }
    }
    let _ = std::fs::remove_dir_all(dir);
}
