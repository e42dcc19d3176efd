//! The study parser returns errors, never panics, on arbitrary and mutated input.

use hd_sweep::parse_study;
use proptest::prelude::*;
use std::path::Path;

const VALID: &str = r#"
name = "prop"
description = "a valid study"
[base]
variant = "damped"
t_end = 0.05
set = { c = 6e4, sigma0 = 2e5 }
[input]
kind = "sine"
voltage = 24.0
freq = 50.0
[solver]
rtol = 1e-6
[metrics]
keep = ["thz_amp", "efficiency"]
cycles = 2
[traces]
keep = false
[[axis]]
name = "Kbar"
logspace = { start = 1e5, stop = 1e7, num = 3 }
zip = "g"
[[axis]]
name = "C0bar"
linspace = { start = 0.1, stop = 0.3, num = 3 }
zip = "g"
[[axis]]
name = "variant"
values = ["linear", "damped"]
"#;

fn parse(text: &str) -> Result<hd_sweep::Study, hd_sweep::StudyError> {
    let loader = |_: &Path| Err("no files in this test".to_string());
    parse_study(text, Path::new("prop.toml"), &loader)
}

#[test]
fn the_reference_study_is_valid_and_expands_as_zipped_times_product() {
    let study = parse(VALID).unwrap();
    assert_eq!(study.expand().len(), 3 * 2);
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 512, ..ProptestConfig::default() })]

    #[test]
    fn arbitrary_text_never_panics(text in ".{0,400}") {
        let _ = parse(&text);
    }

    #[test]
    fn mutated_studies_never_panic(
        cut in 0usize..VALID.len(),
        len in 0usize..40,
        insert in "[a-zA-Z0-9_=\\[\\]{}\",.\\-\\n ]{0,30}",
    ) {
        let mut s = VALID.to_string();
        let start = cut.min(s.len());
        let end = (start + len).min(s.len());
        if s.is_char_boundary(start) && s.is_char_boundary(end) {
            s.replace_range(start..end, &insert);
        }
        if let Err(e) = parse(&s) {
            // Every error is located.
            prop_assert!(e.line >= 1 && e.file == "prop.toml");
        }
    }

    #[test]
    fn numeric_values_are_checked_not_trusted(v in prop::num::f64::ANY) {
        let text = format!("name = \"x\"\n[[axis]]\nname = \"Jz\"\nvalues = [{v:?}]\n");
        match parse(&text) {
            Ok(s) => prop_assert!(v.is_finite() && v > 0.0 && s.expand().len() == 1),
            Err(e) => prop_assert!(e.line >= 1),
        }
    }
}
