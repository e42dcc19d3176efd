//! Draws one figure of each kind and checks every file: a PNG of the figure's size, an SVG
//! carrying its title, nothing else left in the folder. To look at them by eye, keep them:
//! `HD_PLOT_GALLERY=/tmp/gallery cargo test -p hd-plot --test gallery`.
use std::path::{Path, PathBuf};

use hd_plot::*;

#[test]
fn write_figures_for_viewing() {
    let scratch = tempfile::tempdir().unwrap();
    let dir = std::env::var_os("HD_PLOT_GALLERY")
        .map_or_else(|| scratch.path().to_path_buf(), PathBuf::from);
    let _ = std::fs::create_dir_all(&dir);
    let t: Vec<f64> = (0..2000).map(|i| i as f64 * 1e-3).collect();
    let mut trace = hd_model::Trace::default();
    trace.t = t.clone();
    trace.theta_z = t.iter().map(|&t| 3e-4 * (1.0 - (-t * 5.0).exp()) * (t * 20.0).sin()).collect();
    trace.theta = t.iter().map(|&t| 2.5e-4 * (t * 6.0).sin()).collect();
    trace.tb = trace
        .theta
        .iter()
        .enumerate()
        .map(|(i, &th)| 8e4 * th + 3.0 * (t[i] * 6.0).cos())
        .collect();
    response_plot(&dir.join("response.png"), &trace, "Seed case: step response").unwrap();
    response_plot(&dir.join("response.svg"), &trace, "Seed case: step response").unwrap();
    let f: Vec<f64> = (0..200).map(|i| 10f64.powf(-1.0 + 4.0 * i as f64 / 199.0)).collect();
    let series: Vec<Series> = (0..3)
        .map(|k| {
            Series::new(
                format!("ζ = {}", 0.1 * (k + 1) as f64),
                f.clone(),
                f.iter()
                    .map(|&f| {
                        1.0 / ((1.0 - (f / 50.0).powi(2)).powi(2)
                            + (0.2 * (k + 1) as f64 * f / 50.0).powi(2))
                        .sqrt()
                    })
                    .collect(),
            )
        })
        .collect();
    line_plot(&dir.join("lines.png"), "Frequency response", "f [Hz]", "|θz/θj| [–]", &series, true)
        .unwrap();
    let xs: Vec<f64> = (0..12).map(|i| 1e3 * 10f64.powf(i as f64 / 4.0)).collect();
    let ys: Vec<f64> = (0..8).map(|i| 0.05 + 0.05 * i as f64).collect();
    let mut values = Vec::new();
    for (iy, y) in ys.iter().enumerate() {
        for (ix, x) in xs.iter().enumerate() {
            values.push(if ix == 3 && iy == 5 { f64::NAN } else { 1e-4 * x.log10() * y });
        }
    }
    heatmap(
        &dir.join("heatmap.png"),
        "Peak deflection",
        "K0 [N·m/rad]",
        "ζ [–]",
        &xs,
        &ys,
        &values,
        "max |θ| [rad]",
        true,
        false,
    )
    .unwrap();
    let cats: Vec<String> =
        ["K0", "alpha", "Fc", "sigma0", "J_load"].iter().map(|s| s.to_string()).collect();
    let groups = vec![
        BarGroup {
            name: "overshoot".into(),
            values: vec![0.8, 0.3, -0.2, 0.05, f64::NAN],
            intervals: Some(vec![(0.7, 0.9), (0.2, 0.4), (-0.3, -0.1), (0.0, 0.1), (0.0, 0.0)]),
        },
        BarGroup {
            name: "settling time".into(),
            values: vec![0.5, 0.6, 0.1, -0.4, 0.2],
            intervals: None,
        },
    ];
    bar_chart(&dir.join("bars.png"), "Sobol first-order indices", "S1 [–]", &cats, &groups)
        .unwrap();
    let th: Vec<f64> = (0..20000).map(|i| 3e-4 * (i as f64 * 1e-3).sin()).collect();
    let tb_fit: Vec<f64> =
        th.iter().enumerate().map(|(i, &x)| 7e4 * x + 2.0 * (i as f64 * 1e-3).cos()).collect();
    let tb_meas: Vec<f64> = tb_fit
        .iter()
        .enumerate()
        .map(|(i, &y)| y + 0.8 * ((i * 7919 % 1000) as f64 / 500.0 - 1.0))
        .collect();
    let m = Series::new("measured", th.clone(), tb_meas);
    let f = Series::new("model (fitted)", th, tb_fit);
    fit_plot(&dir.join("fit.png"), "Stiffness fit: data vs model", "θ [rad]", "Tb [N·m]", &m, &f)
        .unwrap();
    let r = Series::new("r", m.x.clone(), m.y.iter().zip(&f.y).map(|(a, b)| a - b).collect());
    residual_plot(&dir.join("residuals.png"), "Residuals", "θ [rad]", "Tb [N·m]", &r).unwrap();
    let fb: Vec<f64> = (0..200).map(|i| 10f64.powf(4.0 * i as f64 / 199.0)).collect();
    let curves: Vec<BodeCurve> = (0..2)
        .map(|k| {
            let zeta = 0.1 + 0.3 * k as f64;
            let h: Vec<(f64, f64)> =
                fb.iter().map(|&f| (1.0 - (f / 50.0).powi(2), 2.0 * zeta * f / 50.0)).collect();
            BodeCurve {
                name: format!("ζ = {zeta}"),
                freq: fb.clone(),
                mag_db: h.iter().map(|(re, im)| -10.0 * (re * re + im * im).log10()).collect(),
                phase_deg: h.iter().map(|(re, im)| -im.atan2(*re).to_degrees()).collect(),
            }
        })
        .collect();
    bode_plot(&dir.join("bode.png"), "Second-order plant", &curves).unwrap();
    bode_plot(&dir.join("bode.svg"), "Second-order plant", &curves).unwrap();
    let flat = Series::new("constant", vec![0.0, 1.0, 2.0], vec![2e-4, 2e-4, 2e-4]);
    line_plot(&dir.join("flat.png"), "A constant signal", "t [s]", "θ [rad]", &[flat], false)
        .unwrap();
    let expected = [
        "response.png",
        "response.svg",
        "lines.png",
        "bode.png",
        "bode.svg",
        "heatmap.png",
        "bars.png",
        "fit.png",
        "residuals.png",
        "flat.png",
    ];
    for name in expected {
        check_figure(&dir.join(name));
    }
    let svg = std::fs::read_to_string(dir.join("response.svg")).unwrap();
    assert!(svg.contains("Seed case: step response"), "the SVG lacks its title");
    let bode = std::fs::read_to_string(dir.join("bode.svg")).unwrap();
    assert!(bode.contains("phase [°]") && bode.contains("magnitude [dB]"), "Bode panels");
    let left: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| !expected.contains(&n.as_str()))
        .collect();
    assert!(
        std::env::var_os("HD_PLOT_GALLERY").is_some() || left.is_empty(),
        "temporary files left: {left:?}"
    );
}

/// A PNG with the signature and a plausible size, or a well-formed SVG document.
fn check_figure(path: &Path) {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    if path.extension().unwrap() == "png" {
        assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "{}", path.display());
        let w = u32::from_be_bytes(bytes[16..20].try_into().unwrap());
        let h = u32::from_be_bytes(bytes[20..24].try_into().unwrap());
        assert!((400..=4000).contains(&w) && (300..=4000).contains(&h), "{w}×{h}");
        // A blank image compresses to almost nothing; a drawn figure does not.
        assert!(bytes.len() > 5_000, "{} is only {} bytes", path.display(), bytes.len());
    } else {
        let text = String::from_utf8(bytes).unwrap();
        assert!(text.starts_with("<svg") && text.trim_end().ends_with("</svg>"));
        assert!(text.matches("<path").count() + text.matches("<polyline").count() > 3);
    }
}
