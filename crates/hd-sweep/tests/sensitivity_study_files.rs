//! Study files with `[sample] method = "sobol"` or `"morris"`: the expanded runs carry
//! their design tags and unit coordinates, and bad designs are located errors.

use hd_model::Profile;
use hd_sweep::sensitivity::{Block, PointTag};
use hd_sweep::{Study, StudyError, parse_study};
use std::collections::HashSet;
use std::path::Path;

fn no_profiles(_: &Path) -> Result<Profile, String> {
    Err("no profiles in these tests".into())
}

fn parse(text: &str) -> Result<Study, StudyError> {
    parse_study(text, Path::new("design.toml"), &no_profiles)
}

/// The error's text, which must start with `design.toml:<line>:`.
fn error_at(text: &str, line: usize) -> String {
    let e = parse(text).expect_err("the study should be rejected");
    let shown = e.to_string();
    assert!(shown.starts_with(&format!("design.toml:{line}: ")), "wrong place: {shown}");
    shown
}

const HEAD: &str = r#"name = "d"
[base]
t_end = 0.02
"#;

fn with_sample(sample: &str) -> String {
    format!("{HEAD}{sample}")
}

const SOBOL: &str = r#"[sample]
method = "sobol"
n = 8
seed = 5
[[sample.param]]
name = "c"
lo = 4e4
hi = 6e4
[[sample.param]]
name = "sigma0"
lo = 1e4
hi = 1e6
log = true
[[sample.param]]
name = "Km"
lo = 0.4
hi = 0.6
"#;

#[test]
fn a_sobol_sample_expands_into_a_tagged_saltelli_design() {
    let study = parse(&with_sample(SOBOL)).unwrap();
    let runs = study.expand();
    assert_eq!(runs.len(), 8 * (3 + 2));
    assert_eq!(study.design_names(), ["c", "sigma0", "Km"]);
    assert!(study.has_sensitivity_design());
    for (k, r) in runs.iter().enumerate() {
        let d = r.design.as_ref().expect("every run of the part has a design tag");
        let block = Block::from_position(k % 5, 3).unwrap();
        assert_eq!(d.tag, PointTag::Sobol { base: k / 5, block });
        assert_eq!(d.names, ["c", "sigma0", "Km"]);
        // The unit coordinates map onto the values that were set, linearly or in log.
        let p = &r.config.params;
        assert!((p.c - (4e4 + d.unit[0] * 2e4)).abs() < 1e-6);
        assert!((p.sigma0 - 1e4 * 100f64.powf(d.unit[1])).abs() < 1e-6 * p.sigma0);
        assert!((p.km - (0.4 + d.unit[2] * 0.2)).abs() < 1e-12);
        assert_eq!(&*r.design_names, ["c", "sigma0", "Km"]);
    }
    let ids: HashSet<&str> = runs.iter().map(|r| r.run_id.as_str()).collect();
    assert_eq!(ids.len(), runs.len());
}

#[test]
fn a_morris_sample_gives_unique_ids_even_when_grid_points_repeat() {
    // One parameter on 4 levels: 50 trajectories revisit the same few values many times.
    let text = with_sample(
        r#"[sample]
method = "morris"
trajectories = 50
seed = 2
[[sample.param]]
name = "Km"
lo = 0.4
hi = 0.6
"#,
    );
    let runs = parse(&text).unwrap().expand();
    assert_eq!(runs.len(), 50 * 2);
    let ids: HashSet<&str> = runs.iter().map(|r| r.run_id.as_str()).collect();
    assert_eq!(ids.len(), runs.len(), "the design tag keeps run ids apart");
    let values: HashSet<u64> = runs.iter().map(|r| r.config.params.km.to_bits()).collect();
    assert!(values.len() <= 4, "values lie on the 4-level grid");
    let last = runs.last().unwrap().design.as_ref().unwrap();
    assert_eq!(last.tag, PointTag::Morris { trajectory: 49, step: 1 });
}

#[test]
fn lhs_and_random_samples_work_as_before_and_carry_no_tag() {
    for method in ["lhs", "random"] {
        let text = with_sample(&format!(
            "[sample]\nmethod = \"{method}\"\nn = 7\n[[sample.param]]\nname = \"Km\"\nlo = 0.4\nhi = 0.6\n"
        ));
        let study = parse(&text).unwrap();
        let runs = study.expand();
        assert_eq!(runs.len(), 7);
        assert!(runs.iter().all(|r| r.design.is_none() && r.design_names.is_empty()));
        assert!(!study.has_sensitivity_design());
    }
}

#[test]
fn an_unknown_parameter_is_named_with_a_suggestion_and_its_line() {
    let text = with_sample(&SOBOL.replace("name = \"sigma0\"", "name = \"sigma00\""));
    // Line 13 of the file: HEAD has 3 lines, the name is the 10th line of SOBOL.
    let e = error_at(&text, 13);
    assert!(e.contains("sample.param.name") && e.contains("did you mean 'sigma0'"), "{e}");
}

#[test]
fn bounds_in_the_wrong_order_or_out_of_range_are_errors_at_their_line() {
    let text = with_sample(&SOBOL.replace("hi = 6e4", "hi = 3e4"));
    let e = error_at(&text, 10);
    assert!(e.contains("sample.param 'c'") && e.contains("lo < hi"), "{e}");

    let text = with_sample(&SOBOL.replace("lo = 0.4", "lo = -0.1"));
    let e = error_at(&text, 19);
    assert!(e.contains("sample.param 'Km'") && e.contains("lo:"), "{e}");
}

#[test]
fn a_design_with_grid_axes_in_the_same_part_is_rejected() {
    let text = format!("{HEAD}[[axis]]\nname = \"voltage\"\nvalues = [12, 24]\n{SOBOL}");
    let e = error_at(&text, 7);
    assert!(e.contains("sobol design cannot be combined with grid axes"), "{e}");
    assert!(e.contains("'voltage'"), "{e}");
}

#[test]
fn fields_of_another_method_and_missing_counts_are_errors() {
    let text = with_sample(&SOBOL.replace("n = 8", "trajectories = 8"));
    let e = error_at(&text, 6);
    assert!(e.contains("sample.trajectories") && e.contains("takes 'n'"), "{e}");

    let morris = SOBOL.replace("\"sobol\"", "\"morris\"");
    let e = error_at(&with_sample(&morris), 6);
    assert!(e.contains("sample.n") && e.contains("takes 'trajectories'"), "{e}");

    let text = with_sample(&SOBOL.replace("n = 8\n", ""));
    let e = error_at(&text, 4);
    assert!(e.contains("method 'sobol' needs 'n'"), "{e}");

    let odd = morris.replace("n = 8", "trajectories = 4\nlevels = 3");
    let e = error_at(&with_sample(&odd), 4);
    assert!(e.contains("levels must be an even number"), "{e}");
}

#[test]
fn an_unknown_method_suggests_the_nearest() {
    let text = with_sample(&SOBOL.replace("\"sobol\"", "\"sobel\""));
    let e = error_at(&text, 5);
    assert!(e.contains("did you mean 'sobol'"), "{e}");
}
