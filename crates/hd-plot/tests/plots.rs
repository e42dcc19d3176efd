//! Every figure kind writes a non-empty SVG and PNG, the SVG carries the title, and bad
//! input is an error naming the file rather than a panic or an empty picture.

use std::path::{Path, PathBuf};

use hd_plot::{
    BarGroup, PlotError, Series, bar_chart, fit_plot, heatmap, line_plot, overlay_plot,
    residual_plot, response_plot,
};

/// A fresh folder under the system temp folder, removed when dropped.
struct Scratch(PathBuf);

impl Scratch {
    fn new(name: &str) -> Scratch {
        let dir = std::env::temp_dir().join(format!("hd-plot-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        Scratch(dir)
    }

    fn path(&self, file: &str) -> PathBuf {
        self.0.join(file)
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// Check the file is there and non-empty; for SVG also that it contains `title`.
fn assert_written(path: &Path, title: &str) {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert!(bytes.len() > 1000, "{} is only {} bytes", path.display(), bytes.len());
    if path.extension().is_some_and(|e| e == "svg") {
        let text = String::from_utf8(bytes).unwrap();
        assert!(text.contains(title), "{} lacks the title", path.display());
    } else {
        assert_eq!(&bytes[1..4], b"PNG", "{} is not a PNG", path.display());
    }
}

/// Run `draw` for `name.svg` and `name.png` (in a sub-folder that does not exist yet) and
/// check both files.
fn both_formats(name: &str, title: &str, draw: impl Fn(&Path) -> Result<(), PlotError>) {
    let scratch = Scratch::new(name);
    for ext in ["svg", "png"] {
        let path = scratch.path(&format!("nested/{name}.{ext}"));
        draw(&path).unwrap_or_else(|e| panic!("{e}"));
        assert_written(&path, title);
    }
    // Only the two plots are left behind: no temporary files.
    let left = std::fs::read_dir(scratch.path("nested")).unwrap().count();
    assert_eq!(left, 2);
}

fn trace() -> hd_model::Trace {
    let t: Vec<f64> = (0..500).map(|i| f64::from(i) * 2e-3).collect();
    hd_model::Trace {
        theta_z: t.iter().map(|t| 3e-4 * (20.0 * t).sin()).collect(),
        theta: t.iter().map(|t| 2e-4 * (6.0 * t).sin()).collect(),
        tb: t.iter().map(|t| 15.0 * (6.0 * t).sin() + 2.0 * (6.0 * t).cos()).collect(),
        t,
        ..Default::default()
    }
}

fn sine(name: &str, phase: f64) -> Series {
    let x: Vec<f64> = (1..200).map(|i| f64::from(i) * 0.05).collect();
    let y = x.iter().map(|x| (x + phase).sin()).collect();
    Series::new(name, x, y)
}

#[test]
fn response_plot_writes_both_formats() {
    let trace = trace();
    both_formats("response", "Step response", |p| response_plot(p, &trace, "Step response"));
}

#[test]
fn line_and_overlay_plots_write_both_formats() {
    let series = vec![sine("run 1", 0.0), sine("run 2", 1.0)];
    both_formats("lines", "Sine lines", |p| {
        line_plot(p, "Sine lines", "x [s]", "y [rad]", &series, true)
    });
    both_formats("overlay", "Overlay of runs", |p| {
        overlay_plot(p, "Overlay of runs", "t [s]", "θz [rad]", &series)
    });
}

#[test]
fn heatmap_writes_both_formats_and_notes_missing_cells() {
    let xs = [1.0, 10.0, 100.0, 1000.0];
    let ys = [0.1, 0.2, 0.3];
    let mut values: Vec<f64> = (0..12).map(|i| f64::from(i) * 1e-4).collect();
    values[5] = f64::NAN;
    both_formats("heatmap", "Overshoot map", |p| {
        heatmap(
            p,
            "Overshoot map",
            "K0 [N·m/rad]",
            "ζ [–]",
            &xs,
            &ys,
            &values,
            "overshoot [%]",
            true,
            false,
        )
    });
    let scratch = Scratch::new("heatmap-nan-note");
    let path = scratch.path("h.svg");
    heatmap(&path, "t", "x", "y", &xs, &ys, &values, "v", false, false).unwrap();
    assert!(std::fs::read_to_string(&path).unwrap().contains("grey: NaN"));
}

#[test]
fn bar_chart_writes_both_formats() {
    let categories: Vec<String> = ["K0", "Fc", "J"].iter().map(|s| s.to_string()).collect();
    let groups = vec![
        BarGroup {
            name: "S1".into(),
            values: vec![0.5, 0.2, f64::NAN],
            intervals: Some(vec![(0.4, 0.6), (0.1, 0.3), (f64::NAN, f64::NAN)]),
        },
        BarGroup { name: "ST".into(), values: vec![0.6, -0.1, 0.05], intervals: None },
    ];
    both_formats("bars", "Sensitivity indices", |p| {
        bar_chart(p, "Sensitivity indices", "index [–]", &categories, &groups)
    });
}

#[test]
fn fit_and_residual_plots_write_both_formats() {
    let fitted = sine("model", 0.0);
    let measured = Series::new(
        "data",
        fitted.x.clone(),
        fitted.y.iter().enumerate().map(|(i, y)| y + 0.05 * ((i % 7) as f64 - 3.0)).collect(),
    );
    both_formats("fit", "Fit of sine", |p| {
        fit_plot(p, "Fit of sine", "θ [rad]", "Tb [N·m]", &measured, &fitted)
    });
    // A dense model curve that is not paired with the data: no residual panel, still fine.
    let dense = Series::new("model", vec![0.0, 5.0, 10.0], vec![0.0, 1.0, 0.0]);
    both_formats("fit-unpaired", "Unpaired fit", |p| {
        fit_plot(p, "Unpaired fit", "θ [rad]", "Tb [N·m]", &measured, &dense)
    });
    let residuals = Series::new(
        "r",
        measured.x.clone(),
        measured.y.iter().zip(&fitted.y).map(|(m, f)| m - f).collect(),
    );
    both_formats("residuals", "Fit residuals", |p| {
        residual_plot(p, "Fit residuals", "θ [rad]", "Tb [N·m]", &residuals)
    });
}

#[test]
fn tiny_values_get_scientific_tick_labels() {
    let scratch = Scratch::new("tiny");
    let path = scratch.path("tiny.svg");
    let s = Series::new("θ", vec![0.0, 1.0, 2.0], vec![0.0, 3e-4, 1e-4]);
    line_plot(&path, "tiny", "t [s]", "θ [rad]", &[s], false).unwrap();
    assert!(std::fs::read_to_string(&path).unwrap().contains("3.0e-4"));
}

#[test]
fn all_equal_values_still_plot() {
    let scratch = Scratch::new("flat");
    let flat = Series::new("flat", vec![1.0, 1.0], vec![2.0, 2.0]);
    line_plot(&scratch.path("flat.png"), "flat", "x", "y", &[flat], false).unwrap();
    heatmap(&scratch.path("one.png"), "one", "x", "y", &[1.0], &[1.0], &[5.0], "v", true, true)
        .unwrap();
}

/// The error of a call that must fail, after checking that it left no file.
fn fails(path: &Path, result: Result<(), PlotError>) -> PlotError {
    let err = result.expect_err("the call should fail");
    assert!(!path.exists(), "{} was written", path.display());
    assert!(err.to_string().contains(&path.display().to_string()), "{err}");
    err
}

#[test]
fn all_nan_input_is_an_error_for_every_kind() {
    let scratch = Scratch::new("nan");
    let nan = vec![f64::NAN; 4];
    let nan_series = Series::new("nan", nan.clone(), nan.clone());

    let p = scratch.path("lines.svg");
    let err = fails(&p, line_plot(&p, "t", "x", "y", std::slice::from_ref(&nan_series), false));
    assert!(matches!(err, PlotError::NoFiniteData { .. }), "{err}");

    let p = scratch.path("response.png");
    let trace = hd_model::Trace {
        t: vec![0.0, 1.0, 2.0, 3.0],
        theta_z: nan.clone(),
        theta: nan.clone(),
        tb: nan.clone(),
        ..Default::default()
    };
    let err = fails(&p, response_plot(&p, &trace, "t"));
    assert!(matches!(err, PlotError::NoFiniteData { .. }), "{err}");

    let p = scratch.path("heatmap.svg");
    let err =
        fails(&p, heatmap(&p, "t", "x", "y", &[1.0, 2.0], &[1.0, 2.0], &nan, "v", false, false));
    assert!(matches!(err, PlotError::NoFiniteData { .. }), "{err}");

    let p = scratch.path("bars.svg");
    let group = BarGroup { name: "g".into(), values: nan.clone(), intervals: None };
    let cats: Vec<String> = (0..4).map(|i| i.to_string()).collect();
    let err = fails(&p, bar_chart(&p, "t", "y", &cats, &[group]));
    assert!(matches!(err, PlotError::NoFiniteData { .. }), "{err}");

    let p = scratch.path("fit.svg");
    let err = fails(&p, fit_plot(&p, "t", "x", "y", &nan_series, &sine("m", 0.0)));
    assert!(matches!(err, PlotError::NoFiniteData { .. }), "{err}");

    let p = scratch.path("residuals.svg");
    let err = fails(&p, residual_plot(&p, "t", "x", "y", &nan_series));
    assert!(matches!(err, PlotError::NoFiniteData { .. }), "{err}");
}

#[test]
fn malformed_input_is_an_error() {
    let scratch = Scratch::new("bad");
    let p = scratch.path("a.svg");
    let err = fails(&p, line_plot(&p, "t", "x", "y", &[], false));
    assert!(matches!(err, PlotError::EmptyInput { .. }), "{err}");

    let short = Series::new("short", vec![1.0, 2.0], vec![1.0]);
    let err = fails(&p, line_plot(&p, "t", "x", "y", &[short], false));
    assert!(matches!(err, PlotError::LengthMismatch { expected: 2, found: 1, .. }), "{err}");

    let negative = Series::new("neg", vec![-1.0, -2.0], vec![1.0, 2.0]);
    let err = fails(&p, line_plot(&p, "t", "x", "y", &[negative], true));
    assert!(matches!(err, PlotError::NoPositiveData { .. }), "{err}");

    let err =
        fails(&p, heatmap(&p, "t", "x", "y", &[2.0, 1.0], &[1.0], &[1.0, 2.0], "v", false, false));
    assert!(matches!(err, PlotError::InvalidGrid { .. }), "{err}");
    let err = fails(&p, heatmap(&p, "t", "x", "y", &[1.0, 2.0], &[1.0], &[1.0], "v", false, false));
    assert!(matches!(err, PlotError::LengthMismatch { .. }), "{err}");

    let err = fails(&p, response_plot(&p, &hd_model::Trace::default(), "t"));
    assert!(matches!(err, PlotError::EmptyInput { .. }), "{err}");

    let p = scratch.path("a.pdf");
    let err = fails(&p, line_plot(&p, "t", "x", "y", &[sine("s", 0.0)], false));
    assert!(matches!(err, PlotError::UnsupportedFormat { .. }), "{err}");
}
