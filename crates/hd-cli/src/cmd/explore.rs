//! `hdw explore`: summaries, filters, group-by tables and pivots of result tables, from
//! one Parquet file, a folder of shards or a pattern. The queries run in `hd-io`.

use anyhow::{Result, bail};
use clap::{Args, ValueEnum};
use hd_io::explore::{
    AggSpec, Dataset, Format, Kind, PivotSpec, SortSpec, parse_aggs, parse_pivot, parse_sort,
    render,
};

/// Summarise, filter, group and pivot result tables (runs.parquet, shards, traces).
#[derive(Args, Debug)]
#[command(
    after_help = "Without --group-by, --agg or --pivot it prints the columns with their units, the row count,\nthe failed runs and the count, min, median and max of every metric (after any --filter).\n\nFilters (repeatable, all must hold): COL OP VALUE with OP one of == != < <= > >=, or\nCOL in [A, B]; values are numbers, bare words or quoted texts. Functions for --agg and\n--pivot: count, mean, median, min, max, sum, std. Group-by tables always have n (rows)\nand, for run tables, failed. --format csv prints only the result table; json prints\neverything. Column units are listed in docs/columns.md.\n\nExample:\n  hdw explore out/table4\n  hdw explore out/table4 --filter 'status == \"ok\"' --filter 'Kbar > 5e5' --group-by part --agg thz_amp:max,tb_peak:mean\n  hdw explore 'out/slices/runs-shard-*.parquet' --filter 'part == damped-sine' --pivot Kbar,C0bar,thz_amp:max --format markdown"
)]
pub struct ExploreArgs {
    /// A Parquet file, a folder (its runs*.parquet files) or a pattern such as 'DIR/runs-*.parquet'.
    #[arg(value_name = "FILE_OR_DIR")]
    pub source: String,
    /// Keep rows where EXPR holds, e.g. 'Kbar > 5e5' or 'variant in [full, damped]'.
    #[arg(long, value_name = "EXPR")]
    pub filter: Vec<String>,
    /// Columns to group by, comma-separated.
    #[arg(long, value_name = "COLS", value_delimiter = ',')]
    pub group_by: Vec<String>,
    /// Aggregates per group, METRIC:FN comma-separated (bare METRIC: mean).
    #[arg(long, value_name = "METRIC:FN,...")]
    pub agg: Vec<String>,
    /// Pivot table: values of ROW down, of COL across, FN (default mean) of METRIC in the cells.
    #[arg(long, value_name = "ROW,COL,METRIC[:FN]")]
    pub pivot: Option<String>,
    /// Order the result by one of its columns: COL, COL:asc or COL:desc.
    #[arg(long, value_name = "COL[:desc]")]
    pub sort: Option<String>,
    /// In a folder, read the traces*.parquet files instead of the run tables.
    #[arg(long)]
    pub traces: bool,
    /// Output format.
    #[arg(long, default_value = "table")]
    pub format: FormatArg,
}

/// Output formats.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum FormatArg {
    /// Aligned text with units in the headers.
    Table,
    /// Comma-separated values of the result table.
    Csv,
    /// Markdown tables.
    Markdown,
    /// One JSON object.
    Json,
}

impl From<FormatArg> for Format {
    fn from(f: FormatArg) -> Format {
        match f {
            FormatArg::Table => Format::Table,
            FormatArg::Csv => Format::Csv,
            FormatArg::Markdown => Format::Markdown,
            FormatArg::Json => Format::Json,
        }
    }
}

/// What to compute.
#[derive(Debug, PartialEq)]
pub enum Query {
    /// Schema, rows, failures, metric statistics.
    Summary,
    /// A group-by table (no keys: one row over everything).
    GroupBy { keys: Vec<String>, aggs: Vec<AggSpec>, sort: Option<SortSpec> },
    /// A pivot table.
    Pivot { spec: PivotSpec, sort: Option<SortSpec> },
}

/// Check the options into a query before reading anything.
pub fn query(args: &ExploreArgs) -> Result<Query> {
    let sort = args.sort.as_deref().map(parse_sort).transpose()?;
    let aggs = parse_aggs(&args.agg)?;
    if let Some(p) = &args.pivot {
        if !args.group_by.is_empty() || !aggs.is_empty() {
            bail!(
                "--pivot cannot be combined with --group-by or --agg; give the function in --pivot ROW,COL,METRIC:FN"
            );
        }
        return Ok(Query::Pivot { spec: parse_pivot(p)?, sort });
    }
    if args.group_by.is_empty() && aggs.is_empty() {
        if sort.is_some() {
            bail!(
                "--sort orders a --group-by, --agg or --pivot result; the summary has a fixed order"
            );
        }
        return Ok(Query::Summary);
    }
    Ok(Query::GroupBy { keys: args.group_by.clone(), aggs, sort })
}

/// Run `hdw explore`.
pub fn run(args: ExploreArgs) -> Result<()> {
    let q = query(&args)?;
    let want = args.traces.then_some(Kind::Traces);
    let ds = Dataset::open(&args.source, want)?.filtered(&args.filter)?;
    let report = match &q {
        Query::Summary => ds.summary()?,
        Query::GroupBy { keys, aggs, sort } => ds.group_by(keys, aggs, sort.as_ref())?,
        Query::Pivot { spec, sort } => ds.pivot(spec, sort.as_ref())?,
    };
    print!("{}", render(&report, args.format.into()));
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        args: ExploreArgs,
    }

    fn q(argv: &[&str]) -> Result<Query> {
        query(&Cli::try_parse_from([&["hdw", "runs.parquet"], argv].concat())?.args)
    }

    #[test]
    fn options_become_one_query() {
        assert_eq!(q(&[]).unwrap(), Query::Summary);
        assert!(
            matches!(q(&["--group-by", "variant,Kbar"]).unwrap(), Query::GroupBy { keys, .. } if keys.len() == 2)
        );
        assert!(matches!(q(&["--pivot", "Kbar,voltage,thz_amp"]).unwrap(), Query::Pivot { .. }));
        assert!(q(&["--pivot", "a,b,c", "--agg", "x:max"]).is_err());
        assert!(q(&["--sort", "n"]).is_err());
    }
}
