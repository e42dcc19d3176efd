//! A polars-free table of named columns, as the sweep and the identifier hand it to the I/O
//! crate for writing. Units and descriptions are not stored here: the writer looks each
//! column up in [`crate::schema`], the one place they are kept.

/// The cells of one column.
#[derive(Clone, Debug, PartialEq)]
pub enum Cells {
    /// Numbers; NaN is written as null (undefined, never a made-up value).
    F64(Vec<f64>),
    /// Counts.
    U64(Vec<u64>),
    /// Counts that may be missing.
    OptU64(Vec<Option<u64>>),
    /// Text.
    Text(Vec<String>),
    /// Text that may be missing.
    OptText(Vec<Option<String>>),
}

impl Cells {
    /// Number of cells.
    pub fn len(&self) -> usize {
        match self {
            Cells::F64(v) => v.len(),
            Cells::U64(v) => v.len(),
            Cells::OptU64(v) => v.len(),
            Cells::Text(v) => v.len(),
            Cells::OptText(v) => v.len(),
        }
    }

    /// Whether there are no cells.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// One named column.
#[derive(Clone, Debug, PartialEq)]
pub struct OutColumn {
    /// Column name (a name of [`crate::schema`]).
    pub name: String,
    /// Its cells.
    pub cells: Cells,
}

/// Named columns of equal length, in output order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct OutTable {
    /// The columns.
    pub columns: Vec<OutColumn>,
}

impl OutTable {
    /// Append a column.
    pub fn push(&mut self, name: impl Into<String>, cells: Cells) {
        self.columns.push(OutColumn { name: name.into(), cells });
    }

    /// Number of rows (0 without columns).
    pub fn height(&self) -> usize {
        self.columns.first().map_or(0, |c| c.cells.len())
    }

    /// The column names, in order.
    pub fn names(&self) -> Vec<&str> {
        self.columns.iter().map(|c| c.name.as_str()).collect()
    }
}
