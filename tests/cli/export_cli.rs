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

/// A 64-byte ELF header: 64-bit, little-endian, of type `kind` (3: shared object) for
/// machine `machine` (62: x86-64); nothing after it.
fn elf_header(kind: u16, machine: u16) -> Vec<u8> {
    let mut h = vec![0u8; 64];
    h[..4].copy_from_slice(b"\x7fELF");
    (h[4], h[5], h[6]) = (2, 1, 1);
    h[16..18].copy_from_slice(&kind.to_le_bytes());
    h[18..20].copy_from_slice(&machine.to_le_bytes());
    h
}

#[test]
fn lib_must_be_a_linux_shared_library_exporting_the_fmi_functions() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.fmu");
    let o = out.to_str().unwrap();
    let file = |name: &str, bytes: &[u8]| {
        let p = dir.path().join(name);
        std::fs::write(&p, bytes).unwrap();
        p.to_str().unwrap().to_string()
    };
    let folder = dir.path().join("lib.so");
    std::fs::create_dir(&folder).unwrap();
    let cases: Vec<(String, &[&str])> = vec![
        ("/dev/zero".to_string(), &["/dev/zero", "not a regular file", "ELF shared library"]),
        (folder.to_str().unwrap().to_string(), &["lib.so", "is a folder", "libhd_fmu.so"]),
        (file("notes.txt", b"just some notes\n"), &["notes.txt", "a text file", "no ELF magic"]),
        (file("empty.so", b""), &["empty.so", "is empty"]),
        (file("win.dll", b"MZ\x90\0\x03\0\0\0"), &["win.dll", "PE (Windows)"]),
        (file("mac.dylib", &[0xcf, 0xfa, 0xed, 0xfe, 7, 0, 0, 1]), &["mac.dylib", "Mach-O"]),
        (file("exe", &elf_header(2, 62)), &["exe", "ELF executable"]),
        (file("arm.so", &elf_header(3, 183)), &["arm.so", "aarch64"]),
        (file("other.so", &elf_header(3, 62)), &["other.so", "without fmi2DoStep"]),
    ];
    for (lib, needles) in &cases {
        let r = hdw(&["export", "fmu", "--lib", lib, "--out", o]);
        assert_one_line_error(&r, needles);
        assert!(!out.exists(), "nothing written for --lib {lib}");
    }
    // $HDW_FMU_LIB is checked the same way.
    let r = std::process::Command::new(env!("CARGO_BIN_EXE_hdw"))
        .args(["export", "fmu", "--out", o])
        .env("HDW_FMU_LIB", &cases[2].0)
        .output()
        .unwrap();
    assert_one_line_error(&r, &["notes.txt", "a text file"]);
}
