//! `hdw export fmu`: the archive's parts, the params it carries, and clear errors.

use crate::common::*;
use std::io::Read;

fn entry(archive: &mut zip::ZipArchive<std::fs::File>, name: &str) -> Vec<u8> {
    let mut f = archive.by_name(name).unwrap_or_else(|_| panic!("{name} missing"));
    let mut bytes = Vec::new();
    f.read_to_end(&mut bytes).unwrap();
    bytes
}

#[test]
fn the_fmu_holds_description_binary_and_configuration() {
    let dir = tempfile::tempdir().unwrap();
    let params = dir.path().join("p.toml");
    std::fs::write(&params, "stiffness = \"maxwell-slip\"\nc = 61000.0\n").unwrap();
    for (fmi, platform) in [("2", "linux64"), ("3", "x86_64-linux")] {
        let out = dir.path().join(format!("d{fmi}.fmu"));
        let (p, o) = (params.to_str().unwrap(), out.to_str().unwrap());
        hdw_ok(&["export", "fmu", "--params", p, "--fmi", fmi, "--out", o]);
        let mut zip = zip::ZipArchive::new(std::fs::File::open(&out).unwrap()).unwrap();
        let xml = String::from_utf8(entry(&mut zip, "modelDescription.xml")).unwrap();
        assert!(xml.contains(&format!("fmiVersion=\"{fmi}.0\"")), "{xml}");
        assert!(xml.contains("name=\"c\"") && xml.contains("start=\"61000.0\""));
        assert!(xml.contains("maxwell-slip stiffness"));
        let so = entry(&mut zip, &format!("binaries/{platform}/hd_fmu.so"));
        assert_eq!(&so[..4], b"\x7fELF");
        let toml = String::from_utf8(entry(&mut zip, "resources/model.toml")).unwrap();
        assert!(toml.contains("c = 61000.0") && toml.contains("stiffness = \"maxwell-slip\""));
        // The description's token is the configuration's.
        assert!(xml.contains(&hd_fmu::config::token(&toml)));
    }
}

#[test]
fn bad_values_and_a_missing_binary_are_one_line_errors() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.fmu");
    let o = out.to_str().unwrap();
    let bad = hdw(&["export", "fmu", "--set", "sigma0=-1", "--out", o]);
    assert_one_line_error(&bad, &["sigma0", "expected a finite value > 0"]);
    let missing = hdw(&["export", "fmu", "--lib", "/nonexistent/libhd_fmu.so", "--out", o]);
    assert_one_line_error(&missing, &["/nonexistent/libhd_fmu.so", "does not exist"]);
    assert!(!out.exists(), "nothing written on failure");
    let help = ok(&hdw(&["export", "fmu", "--help"]));
    assert!(help.trim_end().lines().rev().take(5).any(|l| l.contains("hdw export fmu")), "{help}");
}
