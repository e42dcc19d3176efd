//! Which files of a study folder `hdw report` merges, and where the shard tables go after.
//!
//! A sharded study leaves `runs-shard-K-of-N.parquet` (and `traces-shard-K-of-N.parquet`)
//! for every finished shard, and `parts/runs-shard-K-of-N-SEQ.parquet` for the batches an
//! unfinished shard had committed before it stopped. When any of those exist, they are the
//! sources and `runs.parquet` / `traces.parquet` are outputs, rebuilt from them. Once
//! merged, the shard tables move to `shards/`, so that the folder holds each run once for
//! `hdw explore DIR` and for `runs*.parquet` globs in polars or DuckDB; a later `hdw report`
//! reads them there. A folder without shards (one machine, perhaps interrupted) has
//! `runs.parquet` and its own parts as sources.

use anyhow::{Context, Result};
use std::path::{Path, PathBuf};

/// Sub-folder of the shard tables already merged by `hdw report`.
pub const MERGED_SHARDS: &str = "shards";

/// The source files of one kind (`runs` or `traces`), in merge order: finished shards (new
/// ones in DIR, then those merged before in `shards/`), then committed parts, then
/// (one-machine folders only) the existing final table.
#[derive(Debug, Default)]
pub struct Sources {
    /// Final tables of finished shards.
    pub shards: Vec<PathBuf>,
    /// Committed parts of unfinished sweeps.
    pub parts: Vec<PathBuf>,
    /// `runs.parquet` / `traces.parquet` of a folder without shards.
    pub whole: Option<PathBuf>,
}

impl Sources {
    /// Every source, in merge order (the first row of a run wins).
    pub fn all(&self) -> Vec<PathBuf> {
        let mut v = self.shards.clone();
        v.extend(self.parts.iter().cloned());
        v.extend(self.whole.clone());
        v
    }
}

/// Find the sources of `kind` (`runs` or `traces`) in `dir`.
pub fn find_sources(dir: &Path, kind: &str) -> Result<Sources> {
    let shard_prefix = format!("{kind}-shard-");
    let is_shard = |n: &str| n.starts_with(&shard_prefix) && n.ends_with(".parquet");
    let mut shards = list(dir, is_shard)?;
    let merged = dir.join(MERGED_SHARDS);
    if merged.is_dir() {
        shards.extend(list(&merged, is_shard)?);
    }
    let part_prefix = format!("{kind}-");
    let parts_dir = dir.join("parts");
    let parts = if parts_dir.is_dir() {
        list(&parts_dir, |n| n.starts_with(&part_prefix) && n.ends_with(".parquet"))?
    } else {
        Vec::new()
    };
    let whole_path = dir.join(format!("{kind}.parquet"));
    let has_shards = !shards.is_empty() || parts.iter().any(|p| name_of(p).contains("-shard-"));
    let whole = (!has_shards && whole_path.exists()).then_some(whole_path);
    Ok(Sources { shards, parts, whole })
}

/// The N of `runs-shard-K-of-N…` names when every shard file agrees on one; `None` for
/// a folder without shards or with mixed shard counts.
pub fn shard_count(sources: &Sources) -> Option<usize> {
    let mut counts = sources.shards.iter().chain(&sources.parts).filter_map(|p| {
        let name = name_of(p);
        let rest = name.split_once("-of-")?.1;
        let digits: String = rest.chars().take_while(char::is_ascii_digit).collect();
        digits.parse::<usize>().ok()
    });
    let first = counts.next()?;
    counts.all(|n| n == first).then_some(first)
}

/// Move the shard tables of `sources` that are still in `dir` to `dir/shards/` (replacing
/// an older copy there); returns how many moved.
pub fn move_merged_shards(dir: &Path, sources: &Sources) -> Result<usize> {
    let target = dir.join(MERGED_SHARDS);
    let mut moved = 0;
    for f in sources.shards.iter().filter(|f| f.parent() == Some(dir)) {
        std::fs::create_dir_all(&target)
            .with_context(|| format!("cannot create {}", target.display()))?;
        let to = target.join(name_of(f));
        std::fs::rename(f, &to)
            .with_context(|| format!("cannot move {} to {}", f.display(), to.display()))?;
        moved += 1;
    }
    Ok(moved)
}

fn name_of(p: &Path) -> &str {
    p.file_name().and_then(|n| n.to_str()).unwrap_or("")
}

/// Files in `dir` whose names pass `keep`, in name order (so shard 1 comes before 2 and
/// parts in commit order). Temporaries (`.name.tmp-…`) start with a dot and never match.
fn list(dir: &Path, keep: impl Fn(&str) -> bool) -> Result<Vec<PathBuf>> {
    let entries =
        std::fs::read_dir(dir).with_context(|| format!("cannot list {}", dir.display()))?;
    let mut files: Vec<PathBuf> =
        entries.filter_map(|e| e.ok().map(|e| e.path())).filter(|p| keep(name_of(p))).collect();
    files.sort();
    Ok(files)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn touch(dir: &Path, name: &str) {
        std::fs::write(dir.join(name), b"").unwrap();
    }

    #[test]
    fn shards_and_parts_are_sources_and_the_merged_table_is_not() {
        let dir = std::env::temp_dir().join(format!("hdw-report-inputs-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(dir.join("parts")).unwrap();
        for n in ["runs.parquet", "runs-shard-2-of-3.parquet", "runs-shard-1-of-3.parquet"] {
            touch(&dir, n);
        }
        touch(&dir.join("parts"), "runs-shard-3-of-3-000001.parquet");
        touch(&dir.join("parts"), "traces-shard-3-of-3-000001.parquet");
        touch(&dir.join("parts"), ".runs-shard-3-of-3-000002.parquet.tmp-9");
        let s = find_sources(&dir, "runs").unwrap();
        let all = s.all();
        let names: Vec<&str> = all.iter().map(|p| name_of(p)).collect();
        assert_eq!(
            names,
            [
                "runs-shard-1-of-3.parquet",
                "runs-shard-2-of-3.parquet",
                "runs-shard-3-of-3-000001.parquet"
            ]
        );
        assert_eq!(shard_count(&s), Some(3));
        assert_eq!(move_merged_shards(&dir, &s).unwrap(), 2);
        assert!(dir.join("shards/runs-shard-2-of-3.parquet").exists());
        assert!(!dir.join("runs-shard-2-of-3.parquet").exists());
        let again = find_sources(&dir, "runs").unwrap();
        assert_eq!(again.shards.len(), 2, "merged shards are still sources");
        assert_eq!(again.whole, None);
        touch(&dir, "runs-shard-1-of-2.parquet");
        assert_eq!(shard_count(&find_sources(&dir, "runs").unwrap()), None, "mixed counts");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_folder_without_shards_uses_its_own_table() {
        let dir = std::env::temp_dir().join(format!("hdw-report-whole-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        touch(&dir, "runs.parquet");
        let s = find_sources(&dir, "runs").unwrap();
        assert_eq!(s.all(), [dir.join("runs.parquet")]);
        assert_eq!(shard_count(&s), None);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
