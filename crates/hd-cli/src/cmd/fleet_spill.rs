//! A spill file of fixed-width records of numbers, grouped in regions (one per parameter
//! × unit) whose sizes are counted first: the drift stage writes every estimate into its
//! unit's region as fits.parquet streams by (sorted by log), then reads one unit's
//! estimates of one parameter at a time. Memory holds one region, not the fleet.
//!
//! The file is a hidden temporary beside the outputs (hd-io's staged file: removed when
//! dropped, and on an interrupt).

use anyhow::{Context, Result};
use hd_io::atomic::Staged;
use std::fs::File;
use std::io::{Read, Seek, SeekFrom, Write};
use std::path::Path;

/// Records of `width` numbers [f64] in a temporary file.
pub struct Spill {
    _staged: Staged,
    file: File,
    width: usize,
    name: String,
}

impl Spill {
    /// A new, empty spill beside `dest` (which is never written).
    pub fn new(dest: &Path, width: usize) -> Result<Self> {
        let staged = Staged::new(dest)?;
        let file =
            std::fs::OpenOptions::new().read(true).write(true).open(staged.path()).with_context(
                || format!("{}: cannot open the spill file", staged.path().display()),
            )?;
        let name = staged.path().display().to_string();
        Ok(Spill { _staged: staged, file, width: width.max(1), name })
    }

    /// Numbers per record.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Write consecutive records from record `first` on (`values.len()` a multiple of the
    /// width).
    pub fn put(&self, first: usize, values: &[f64]) -> Result<()> {
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        let mut f = &self.file;
        f.seek(SeekFrom::Start((first * self.width * 8) as u64))
            .and_then(|_| f.write_all(&bytes))
            .with_context(|| format!("{}: cannot write the spill file", self.name))
    }

    /// Read `n` consecutive records from record `first` on.
    pub fn get(&self, first: usize, n: usize) -> Result<Vec<f64>> {
        let mut bytes = vec![0u8; n * self.width * 8];
        let mut f = &self.file;
        f.seek(SeekFrom::Start((first * self.width * 8) as u64))
            .and_then(|_| f.read_exact(&mut bytes))
            .with_context(|| format!("{}: cannot read the spill file", self.name))?;
        Ok(bytes
            .chunks_exact(8)
            .map(|b| f64::from_le_bytes(b.try_into().unwrap_or([0; 8])))
            .collect())
    }

    /// Write `records` (record index, its numbers) in as few writes as there are runs of
    /// consecutive indices.
    pub fn put_all(&self, records: &mut [(usize, Vec<f64>)]) -> Result<()> {
        records.sort_by_key(|r| r.0);
        let mut k = 0;
        while k < records.len() {
            let mut end = k + 1;
            while end < records.len() && records[end].0 == records[end - 1].0 + 1 {
                end += 1;
            }
            let run: Vec<f64> = records[k..end].iter().flat_map(|r| r.1.iter().copied()).collect();
            self.put(records[k].0, &run)?;
            k = end;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn records_come_back_where_they_were_put() {
        let dir = std::env::temp_dir().join(format!("hdw-spill-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let s = Spill::new(&dir.join("x.bin"), 2).unwrap();
        let mut recs = vec![(3, vec![3.0, 30.0]), (0, vec![0.0, 0.5]), (1, vec![1.0, f64::NAN])];
        s.put_all(&mut recs).unwrap();
        s.put(2, &[2.0, 20.0]).unwrap();
        let all = s.get(0, 4).unwrap();
        assert_eq!(all[0..2], [0.0, 0.5]);
        assert!(all[3].is_nan());
        assert_eq!(all[4..8], [2.0, 20.0, 3.0, 30.0]);
        assert_eq!(s.get(3, 1).unwrap(), [3.0, 30.0]);
        drop(s);
        let left = std::fs::read_dir(&dir).unwrap().count();
        assert_eq!(left, 0, "the spill is removed when dropped");
        let _ = std::fs::remove_dir_all(dir);
    }
}
