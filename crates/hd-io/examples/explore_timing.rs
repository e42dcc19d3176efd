//! Time the explore engine's queries on a runs table: `cargo run --release -p hd-io
//! --example explore_timing -- FILE_OR_DIR` prints the best of three wall times of
//! opening, the summary, a pivot and a group-by. `-- --generate DIR` first writes the
//! benchmark's 1 000 000-row table to `DIR/one/runs.parquet` and `DIR/shards/`.

#[path = "../benches/runs_like/mod.rs"]
mod runs_like;

use hd_io::explore::{Dataset, parse_aggs, parse_pivot};
use std::time::Instant;

fn time<T>(what: &str, f: impl Fn() -> T) {
    let times: Vec<f64> = (0..3)
        .map(|_| {
            let t0 = Instant::now();
            std::hint::black_box(f());
            t0.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    println!(
        "{what:<28} {:>8.1} ms (runs: {times:.1?})",
        times.iter().cloned().fold(f64::INFINITY, f64::min)
    );
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if let [flag, dir] = &args[..]
        && flag == "--generate"
    {
        runs_like::write_data(std::path::Path::new(dir));
        println!("wrote {} rows to {dir}/one and {dir}/shards", runs_like::ROWS);
        return;
    }
    let Some(src) = args.first().cloned() else {
        eprintln!("usage: explore_timing FILE_OR_DIR [ROW,COL,METRIC]");
        std::process::exit(2);
    };
    let pivot = args.get(1).cloned().unwrap_or_else(|| "Kbar,voltage,thz_amp".into());
    let ds = Dataset::open(&src, None).expect("opens");
    time("open", || Dataset::open(&src, None).unwrap());
    time("summary", || ds.summary().unwrap());
    let ok = ds.clone().filtered(&["status == \"ok\"".into()]).unwrap();
    time("summary (status == ok)", || ok.summary().unwrap());
    let spec = parse_pivot(&pivot).unwrap();
    time("pivot", || ds.pivot(&spec, None).unwrap());
    let aggs = parse_aggs(&["thz_amp:max".into()]).unwrap();
    time("group_by variant", || ds.group_by(&["variant".into()], &aggs, None).unwrap());
}
