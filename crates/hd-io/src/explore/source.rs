//! Where a data set comes from: one Parquet file, a folder of them, or a file-name
//! pattern, resolved to a sorted list of files of one kind.
//!
//! A folder means its `*.parquet` files, not those in sub-folders (so not the `parts/` of
//! an unfinished sweep) and not hidden or temporary ones (`.name`, `*.tmp*`). Run tables
//! (`runs*.parquet`) and traces (`trace*.parquet`) are never read together: a folder gives
//! its run tables unless traces are asked for; a pattern that matches both is an error.

use crate::explore::error::ExploreError;
use std::path::{Path, PathBuf};

/// The kind of table, from the file names.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// `runs.parquet` or `runs-shard-K-of-N.parquet`: one row per run.
    Runs,
    /// `traces*.parquet` (long format, with `run_id`) or the `trace.parquet` of one run.
    Traces,
    /// Any other Parquet file.
    Other,
}

impl Kind {
    /// The kind a file name announces.
    pub fn of(path: &Path) -> Kind {
        let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
        if name.starts_with("runs") {
            Kind::Runs
        } else if name.starts_with("trace") {
            Kind::Traces
        } else {
            Kind::Other
        }
    }

    fn pattern(self) -> &'static str {
        match self {
            Kind::Runs => "runs*.parquet",
            Kind::Traces => "traces*.parquet",
            Kind::Other => "*.parquet",
        }
    }
}

/// The files of one data set.
#[derive(Clone, Debug, PartialEq)]
pub struct Source {
    /// The file, folder or pattern as given.
    pub name: String,
    /// The Parquet files, sorted by name.
    pub files: Vec<PathBuf>,
    /// Their kind.
    pub kind: Kind,
}

/// Resolve `spec` (file, folder or pattern with `*` / `?` in the file name) to files.
/// `want` picks the kind in a folder holding several (default: run tables).
pub fn resolve(spec: &str, want: Option<Kind>) -> Result<Source, ExploreError> {
    let path = Path::new(spec);
    let err = |m: String| ExploreError::source(spec, m);
    let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
    if name.contains(['*', '?']) {
        let dir = path.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
        if dir.to_string_lossy().contains(['*', '?']) {
            return Err(err("only the file-name part of a pattern may hold * or ?".into()));
        }
        let files: Vec<PathBuf> =
            list_parquet(dir, spec)?.into_iter().filter(|f| matches(name, file_name(f))).collect();
        let kind = single_kind(&files).ok_or_else(|| {
            err("the pattern matches both run tables and traces; narrow it, e.g. runs*.parquet"
                .into())
        })?;
        return finish(spec, files, kind);
    }
    if path.is_dir() {
        let all = list_parquet(path, spec)?;
        let of = |k: Kind| all.iter().filter(|f| Kind::of(f) == k).cloned().collect::<Vec<_>>();
        let kind = want.unwrap_or(if of(Kind::Runs).is_empty() && !of(Kind::Traces).is_empty() {
            Kind::Traces
        } else if of(Kind::Runs).is_empty() && of(Kind::Traces).is_empty() {
            Kind::Other
        } else {
            Kind::Runs
        });
        let files = if kind == Kind::Other { all } else { of(kind) };
        if files.is_empty() {
            let unfinished = path.join("parts").is_dir();
            return Err(err(format!(
                "no {} file in the folder{}",
                kind.pattern(),
                if unfinished {
                    "; parts/ holds the parts of an unfinished sweep: finish it with `hdw study --resume`, or read DIR/parts/runs-*.parquet"
                } else {
                    ""
                }
            )));
        }
        return finish(spec, files, kind);
    }
    if !path.is_file() {
        return Err(err("no such file or folder".into()));
    }
    finish(spec, vec![path.to_path_buf()], Kind::of(path))
}

fn finish(spec: &str, files: Vec<PathBuf>, kind: Kind) -> Result<Source, ExploreError> {
    if files.is_empty() {
        return Err(ExploreError::source(spec, "no Parquet file matches"));
    }
    Ok(Source { name: spec.to_string(), files, kind })
}

fn file_name(p: &Path) -> &str {
    p.file_name().and_then(|n| n.to_str()).unwrap_or("")
}

/// The visible, finished `*.parquet` files directly in `dir`, sorted.
fn list_parquet(dir: &Path, spec: &str) -> Result<Vec<PathBuf>, ExploreError> {
    let entries = std::fs::read_dir(dir)
        .map_err(|e| ExploreError::source(spec, format!("cannot list {}: {e}", dir.display())))?;
    let mut files: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.is_file())
        .filter(|p| {
            let n = file_name(p);
            n.ends_with(".parquet") && !n.starts_with('.') && !n.contains(".tmp")
        })
        .collect();
    files.sort();
    Ok(files)
}

/// The one kind all files share, treating run tables and traces as incompatible.
fn single_kind(files: &[PathBuf]) -> Option<Kind> {
    let kinds: Vec<Kind> = files.iter().map(|f| Kind::of(f)).collect();
    let has = |k| kinds.contains(&k);
    match (has(Kind::Runs), has(Kind::Traces)) {
        (true, true) => None,
        (true, false) => Some(Kind::Runs),
        (false, true) => Some(Kind::Traces),
        (false, false) => Some(Kind::Other),
    }
}

/// Whether `name` matches `pattern`, where `*` is any run of characters and `?` one.
fn matches(pattern: &str, name: &str) -> bool {
    let p: Vec<char> = pattern.chars().collect();
    let n: Vec<char> = name.chars().collect();
    let (mut i, mut j) = (0, 0);
    let mut star: Option<(usize, usize)> = None;
    while j < n.len() {
        if i < p.len() && (p[i] == '?' || p[i] == n[j]) {
            i += 1;
            j += 1;
        } else if i < p.len() && p[i] == '*' {
            star = Some((i, j));
            i += 1;
        } else if let Some((si, sj)) = star {
            i = si + 1;
            j = sj + 1;
            star = Some((si, sj + 1));
        } else {
            return false;
        }
    }
    p[i..].iter().all(|&c| c == '*')
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wildcards() {
        assert!(matches("runs*.parquet", "runs-shard-1-of-2.parquet"));
        assert!(matches("runs*.parquet", "runs.parquet"));
        assert!(!matches("runs*.parquet", "traces.parquet"));
        assert!(matches("r?ns.*", "runs.parquet"));
        assert!(!matches("runs", "runs.parquet"));
    }

    #[test]
    fn kinds_by_name() {
        assert_eq!(Kind::of(Path::new("a/runs-shard-2-of-8.parquet")), Kind::Runs);
        assert_eq!(Kind::of(Path::new("trace.parquet")), Kind::Traces);
        assert_eq!(Kind::of(Path::new("fit.parquet")), Kind::Other);
    }
}
