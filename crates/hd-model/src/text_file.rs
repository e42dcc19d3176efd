//! Reading a settings file (params, study) safely: its size and type are checked before a
//! byte of it is parsed, so a path to `/dev/zero`, a folder or a 240 MB data file gives a
//! one-line error instead of filling the memory.

use std::io::Read;
use std::path::Path;

/// Largest settings file read [bytes]: a study with thousands of listed axis values is
/// well under a megabyte.
pub const MAX_SETTINGS_BYTES: u64 = 4 << 20;

/// What a file that is not text is, from its first bytes, if it is recognisably not text:
/// a compressed archive (named) or binary data (a NUL byte).
pub fn binary_kind(head: &[u8]) -> Option<&'static str> {
    const MAGIC: [(&[u8], &str); 7] = [
        (&[0x1f, 0x8b], "gzip-compressed (decompress it first, e.g. gunzip)"),
        (b"PK\x03\x04", "a zip archive (extract it first)"),
        (&[0x28, 0xb5, 0x2f, 0xfd], "zstd-compressed (decompress it first, e.g. unzstd)"),
        (b"BZh", "bzip2-compressed (decompress it first, e.g. bunzip2)"),
        (&[0xfd, b'7', b'z', b'X', b'Z', 0], "xz-compressed (decompress it first, e.g. unxz)"),
        (b"PAR1", "a Parquet file"),
        (b"MATLAB", "a MATLAB .mat file (export the columns as CSV)"),
    ];
    if let Some((_, what)) = MAGIC.iter().find(|(m, _)| head.starts_with(m)) {
        return Some(what);
    }
    head.contains(&0).then_some("binary data, not text")
}

/// Read the text file `path`, refusing a folder, a device or pipe, a file over `max`
/// bytes, and binary or non-UTF-8 content, each with a one-line reason. `what` names the
/// file's role in messages ("params file").
pub fn read_text(path: &Path, what: &str, max: u64) -> Result<String, String> {
    let at = || format!("{what} {}", path.display());
    let meta = std::fs::metadata(path).map_err(|e| format!("cannot read {}: {e}", at()))?;
    if meta.is_dir() {
        return Err(format!("{} is a folder: expected a file", at()));
    }
    if !meta.is_file() {
        return Err(format!("{} is not a regular file (a device or pipe?)", at()));
    }
    if meta.len() > max {
        return Err(format!(
            "{} is {} bytes, more than the {max} a {what} may have: is it the right file?",
            at(),
            meta.len()
        ));
    }
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    std::fs::File::open(path)
        .and_then(|f| f.take(max + 1).read_to_end(&mut bytes))
        .map_err(|e| format!("cannot read {}: {e}", at()))?;
    if bytes.len() as u64 > max {
        return Err(format!("{} grew past {max} bytes while being read", at()));
    }
    if let Some(kind) = binary_kind(&bytes[..bytes.len().min(4096)]) {
        return Err(format!("{} is {kind}: expected a TOML text file", at()));
    }
    String::from_utf8(bytes).map_err(|e| {
        format!(
            "{} is not UTF-8 text (byte {}): expected a TOML text file",
            at(),
            e.utf8_error().valid_up_to()
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn compressed_and_binary_heads_are_named() {
        assert!(binary_kind(&[0x1f, 0x8b, 8, 0]).unwrap().starts_with("gzip"));
        assert!(binary_kind(b"PK\x03\x04rest").unwrap().starts_with("a zip"));
        assert_eq!(binary_kind(b"t,u\n0,\x001\n"), Some("binary data, not text"));
        assert_eq!(binary_kind(b"c = 6e4\n"), None);
    }

    #[test]
    fn folders_devices_and_large_files_are_refused() {
        let dir = std::env::temp_dir();
        assert!(read_text(&dir, "params file", 100).unwrap_err().contains("is a folder"));
        #[cfg(unix)]
        assert!(
            read_text(Path::new("/dev/zero"), "params file", 100)
                .unwrap_err()
                .contains("not a regular file")
        );
        let f = dir.join(format!("hd-model-text-file-{}.toml", std::process::id()));
        std::fs::write(&f, "c = 6e4\n".repeat(20)).unwrap();
        let err = read_text(&f, "params file", 100).unwrap_err();
        assert!(err.contains("160 bytes, more than the 100"), "{err}");
        assert_eq!(read_text(&f, "params file", 1000).unwrap().len(), 160);
        std::fs::remove_file(&f).unwrap();
    }
}
