//! A path pattern (`logs/{robot}/{joint}/{date}.csv`) expanded into a manifest: one row per
//! matching file, its fields as columns.

use crate::error::IoError;
use crate::table::{ColumnData, Table};
use std::path::{Path, PathBuf};

/// Files matching `pattern` (`logs/{robot}/{joint}/{date}.csv`: each `{name}` matches
/// one or more characters within a path component), as a table with the column `file`
/// and one text column per field, sorted by file. Literal leading components are not
/// searched (the walk starts below them).
pub fn expand_pattern(pattern: &str) -> Result<Table, IoError> {
    let comps: Vec<&str> = pattern.split('/').collect();
    let mut fields: Vec<String> = Vec::new();
    for c in &comps {
        for f in field_names(c).map_err(|m| IoError::format(pattern, m))? {
            if fields.contains(&f) {
                return Err(IoError::format(pattern, format!("field '{{{f}}}' appears twice")));
            }
            fields.push(f);
        }
    }
    if fields.is_empty() {
        return Err(IoError::format(
            pattern,
            "no {field} in the pattern: expected e.g. logs/{robot}/{joint}/{date}.csv",
        ));
    }
    let mut found: Vec<(String, Vec<(String, String)>)> = Vec::new();
    let root = if pattern.starts_with('/') { PathBuf::from("/") } else { PathBuf::from(".") };
    walk(&root, pattern.starts_with('/'), &comps, 0, String::new(), Vec::new(), &mut found);
    found.sort();
    let mut t = Table { height: found.len(), ..Default::default() };
    t.names.push("file".into());
    t.columns.push(ColumnData::Text(found.iter().map(|(f, _)| Some(f.clone())).collect()));
    for name in &fields {
        let v = found
            .iter()
            .map(|(_, kv)| kv.iter().find(|(k, _)| k == name).map(|(_, v)| v.clone()))
            .collect();
        t.names.push(name.clone());
        t.columns.push(ColumnData::Text(v));
    }
    Ok(t)
}

fn field_names(comp: &str) -> Result<Vec<String>, String> {
    let mut out = Vec::new();
    let mut rest = comp;
    while let Some(i) = rest.find('{') {
        let Some(j) = rest[i..].find('}') else {
            return Err(format!("'{comp}': a '{{' without '}}'"));
        };
        let name = &rest[i + 1..i + j];
        if name.is_empty() || !name.chars().all(|c| c.is_alphanumeric() || c == '_') {
            return Err(format!("'{{{name}}}': a field name is letters, digits and _"));
        }
        if rest[i + j + 1..].starts_with('{') {
            return Err(format!("'{comp}': two fields must be separated by a literal"));
        }
        out.push(name.to_string());
        rest = &rest[i + j + 1..];
    }
    Ok(out)
}

/// Match `name` against a component pattern; the fields' values on success.
fn match_comp(pat: &str, name: &str) -> Option<Vec<(String, String)>> {
    match pat.find('{') {
        None => (pat == name).then(Vec::new),
        Some(i) => {
            let name_rest = name.strip_prefix(&pat[..i])?;
            let j = pat[i..].find('}')? + i;
            let field = &pat[i + 1..j];
            let after = &pat[j + 1..];
            // Shortest value first for a literal that follows; the whole rest at the end.
            for end in 1..=name_rest.len() {
                if !name_rest.is_char_boundary(end) {
                    continue;
                }
                if let Some(mut rest) = match_comp(after, &name_rest[end..]) {
                    rest.insert(0, (field.to_string(), name_rest[..end].to_string()));
                    return Some(rest);
                }
            }
            None
        }
    }
}

fn walk(
    dir: &Path,
    absolute: bool,
    comps: &[&str],
    k: usize,
    prefix: String,
    kv: Vec<(String, String)>,
    out: &mut Vec<(String, Vec<(String, String)>)>,
) {
    let join = |p: &str, c: &str| {
        if p.is_empty() {
            if absolute { format!("/{c}") } else { c.to_string() }
        } else {
            format!("{p}/{c}")
        }
    };
    let last = k + 1 == comps.len();
    let comp = comps[k];
    if comp.is_empty() && k == 0 {
        walk(dir, absolute, comps, 1, prefix, kv, out);
        return;
    }
    if !comp.contains('{') {
        let path = dir.join(comp);
        let p = join(&prefix, comp);
        if last {
            if path.is_file() {
                out.push((p, kv));
            }
        } else if path.is_dir() {
            walk(&path, absolute, comps, k + 1, p, kv, out);
        }
        return;
    }
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    for e in entries.flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        if name.starts_with('.') {
            continue;
        }
        let Some(vals) = match_comp(comp, &name) else { continue };
        let mut kv2 = kv.clone();
        kv2.extend(vals);
        let path = e.path();
        let p = join(&prefix, &name);
        if last {
            if path.is_file() {
                out.push((p, kv2));
            }
        } else if path.is_dir() {
            walk(&path, absolute, comps, k + 1, p, kv2, out);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_pattern_finds_its_files_and_fields() {
        let dir = std::env::temp_dir().join(format!("hd-io-fleet-pattern-{}", std::process::id()));
        for (r, j, d) in
            [("r1", "j1", "2026-01-01"), ("r1", "j2", "2026-01-02"), ("r2", "j1", "2026-01-01")]
        {
            let p = dir.join(r).join(j);
            std::fs::create_dir_all(&p).unwrap();
            std::fs::write(p.join(format!("{d}.csv")), "t\n").unwrap();
        }
        std::fs::write(dir.join("r1").join("j1").join("notes.txt"), "x").unwrap();
        let pat = format!("{}/{{robot}}/{{joint}}/{{date}}.csv", dir.display());
        let t = expand_pattern(&pat).unwrap();
        assert_eq!(t.height, 3);
        assert_eq!(t.names, ["file", "robot", "joint", "date"]);
        let robots = t.text("robot").unwrap();
        assert_eq!(robots.iter().flatten().filter(|r| *r == "r1").count(), 2);
        assert_eq!(t.text("date").unwrap()[0].as_deref(), Some("2026-01-01"));
        let _ = std::fs::remove_dir_all(dir);
    }
}
