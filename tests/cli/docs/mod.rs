//! The docs are tested: every shell example in README.md, docs/, studies/, data/, deploy/ and
//! benches/ Markdown, and every worked example that ends a `--help`, runs here in order, in a
//! scratch folder that holds a copy of the shipped `studies/` and `data/` (so examples write
//! where a user's would, and inputs come only from the repository or an earlier example).
//! Transcripts (```` ```text ```` blocks starting with `$ `) also check what the command prints,
//! so the figures the docs quote are the ones the code gives. See [`parse`] for the fences.
//!
//! Why not trycmd/snapbox: those compare each block's whole output on its own, from a
//! sandbox per file. Our examples are sequences that share one working tree across files
//! (the explore guide reads the study the README ran), most blocks show commands without
//! their output, and outputs carry wall times; a runner of our own keeps the order, the
//! shared folder and the explicit skip reasons, and checks the quoted lines exactly.

mod parse;

use crate::common::{repo_path, scratch};
use parse::Example;
use std::path::Path;
use std::process::Command;

/// Markdown files in the order their examples build on each other; every other `.md` of
/// the listed folders follows, alphabetically.
const FIRST: &[&str] = &["README.md", "docs/explore.md", "docs/sensitivity.md"];
const FOLDERS: &[&str] = &["docs", "studies", "data", "data/catalogue", "deploy/slurm", "benches"];

fn doc_files() -> Vec<String> {
    let mut files: Vec<String> = FIRST.iter().map(|s| s.to_string()).collect();
    for dir in FOLDERS {
        let mut more: Vec<String> = std::fs::read_dir(repo_path(dir))
            .map(|rd| {
                rd.filter_map(|e| e.ok())
                    .map(|e| format!("{dir}/{}", e.file_name().to_string_lossy()))
                    .filter(|n| n.ends_with(".md") && !files.contains(n))
                    .collect()
            })
            .unwrap_or_default();
        more.sort();
        files.extend(more);
    }
    files
}

fn copy_tree(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap().flatten() {
        let target = to.join(e.file_name());
        if e.file_type().unwrap().is_dir() {
            copy_tree(&e.path(), &target);
        } else {
            std::fs::copy(e.path(), target).unwrap();
        }
    }
}

/// A scratch folder laid out as a clean checkout's inputs, with `hdw` on the PATH.
fn workdir(name: &str) -> (std::path::PathBuf, String) {
    let dir = scratch(name);
    for d in ["studies", "data"] {
        copy_tree(&repo_path(d), &dir.join(d));
    }
    let bin = dir.join(".bin");
    std::fs::create_dir_all(&bin).unwrap();
    std::os::unix::fs::symlink(env!("CARGO_BIN_EXE_hdw"), bin.join("hdw")).unwrap();
    let path = format!("{}:{}", bin.display(), std::env::var("PATH").unwrap_or_default());
    (dir, path)
}

/// What a documented command becomes here: the README's first command is `hdw` itself;
/// `cargo test` is this suite. `Err(reason)` for a command not run.
fn translate(cmd: &str) -> Result<String, String> {
    if let Some(rest) = cmd.strip_prefix("cargo run --release -p hd-cli --") {
        return Ok(format!("hdw{rest}"));
    }
    if cmd.starts_with("cargo test") {
        return Err("the test suite itself (this test runs inside it)".into());
    }
    Ok(cmd.to_string())
}

/// The outcome of the examples of one run.
#[derive(Default)]
struct Tally {
    ran: usize,
    checked: usize,
    skipped: Vec<String>,
    failures: Vec<String>,
}

fn run_all(examples: &[Example], dir: &Path, path: &str, tally: &mut Tally) {
    for ex in examples {
        let cmd = match (ex.skip.clone(), translate(&ex.command)) {
            (Some(reason), _) | (None, Err(reason)) => {
                tally.skipped.push(format!("{}: `{}` — {reason}", ex.place, ex.command));
                continue;
            }
            (None, Ok(cmd)) => cmd,
        };
        let out = Command::new("timeout")
            .args(["900", "bash", "-c", &format!("set -euo pipefail\n{cmd}")])
            .current_dir(dir)
            .env("PATH", path)
            .env("NO_COLOR", "1")
            .output()
            .expect("run bash");
        tally.ran += 1;
        let stdout = String::from_utf8_lossy(&out.stdout);
        let stderr = String::from_utf8_lossy(&out.stderr);
        let expect_failure = ex.expect.iter().any(|l| l.starts_with("error:"));
        if out.status.success() == expect_failure {
            tally.failures.push(format!(
                "{}: `{cmd}` exited {:?} (expected {}):\n{}{}",
                ex.place,
                out.status.code(),
                if expect_failure { "a failure" } else { "success" },
                tail(&stdout),
                tail(&stderr)
            ));
            continue;
        }
        if !ex.expect.is_empty() {
            tally.checked += 1;
            let printed: Vec<&str> =
                stdout.lines().chain(stderr.lines()).map(str::trim_end).collect();
            let mut at = 0;
            for want in ex.expect.iter().filter(|l| l.trim() != "...") {
                match printed[at..].iter().position(|l| same_line(want, l)) {
                    Some(k) => at += k + 1,
                    None => {
                        tally.failures.push(format!(
                            "{}: `{cmd}` did not print, in order, the documented line\n  {want}\nit printed:\n{}{}",
                            ex.place, stdout, stderr
                        ));
                        break;
                    }
                }
            }
        }
    }
}

/// Whether a printed line is the documented one: the same words, and numbers equal to 1e-5
/// of their size. The slack absorbs the last-digit wobble of a solve built for another CPU
/// (fused multiply–adds change rounding); a dropped digit, a changed figure in the fifth
/// significant digit or a moved column are still caught.
fn same_line(want: &str, got: &str) -> bool {
    let (w, g): (Vec<&str>, Vec<&str>) =
        (want.split_whitespace().collect(), got.split_whitespace().collect());
    w.len() == g.len()
        && w.iter().zip(&g).all(|(a, b)| {
            // `[..]` stands for a figure the docs do not pin (a rounding residual).
            if a == b || *a == "[..]" {
                return true;
            }
            let num = |t: &str| t.trim_end_matches([',', ';', ')']).parse::<f64>().ok();
            match (num(a), num(b)) {
                (Some(x), Some(y)) => (x - y).abs() <= 1e-5 * x.abs().max(y.abs()),
                _ => false,
            }
        })
}

#[test]
fn documented_lines_match_with_number_slack_only() {
    assert!(same_line("  142510  4.20108e-4", "142510 4.201081e-4"));
    assert!(!same_line("142510  x", "14251  x"));
    assert!(!same_line("tb 0.819788", "tb 0.819855"));
    assert!(!same_line("a b", "a b c"));
    assert!(same_line("rms [..] N·m", "rms 2.9e-8 N·m"));
}

fn tail(s: &str) -> String {
    let lines: Vec<&str> = s.lines().collect();
    lines[lines.len().saturating_sub(15)..].join("\n") + "\n"
}

/// Writes the tally where CI prints it and fails with every failure.
fn report(name: &str, tally: &Tally) {
    let mut text = format!(
        "{name}: {} commands run ({} transcripts checked against the docs), {} documented but not run:\n",
        tally.ran,
        tally.checked,
        tally.skipped.len()
    );
    for s in &tally.skipped {
        text.push_str(&format!("  skipped {s}\n"));
    }
    let summary = repo_path("target").join(format!("{name}.txt"));
    let _ = std::fs::write(&summary, &text);
    eprint!("{text}");
    assert!(
        tally.failures.is_empty(),
        "{} documented command(s) failed:\n\n{}",
        tally.failures.len(),
        tally.failures.join("\n\n")
    );
}

#[test]
fn every_documented_command_runs_and_prints_what_the_docs_quote() {
    let (dir, path) = workdir("docs");
    let mut tally = Tally::default();
    let mut examples = Vec::new();
    for file in doc_files() {
        let text = std::fs::read_to_string(repo_path(&file)).unwrap();
        match parse::markdown(&file, &text) {
            Ok(ex) => examples.extend(ex),
            Err(e) => tally.failures.push(e),
        }
    }
    assert!(examples.len() > 40, "only {} examples found", examples.len());
    run_all(&examples, &dir, &path, &mut tally);
    report("docs-test-summary", &tally);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn every_help_example_runs() {
    let help = |args: &[&str]| {
        let out = Command::new(env!("CARGO_BIN_EXE_hdw")).args(args).output().unwrap();
        String::from_utf8_lossy(&out.stdout).into_owned()
    };
    // The subcommands a help text lists under `Commands:`.
    let listed = |text: &str| -> Vec<String> {
        text.lines()
            .skip_while(|l| !l.starts_with("Commands:"))
            .skip(1)
            .take_while(|l| l.starts_with("  "))
            .filter_map(|l| l.split_whitespace().next().map(str::to_string))
            .filter(|c| c != "help")
            .collect()
    };
    let top = help(&["--help"]);
    let subcommands = listed(&top);
    assert!(subcommands.len() >= 8, "subcommands: {subcommands:?}");
    let mut tally = Tally::default();
    let mut all = vec![("hdw".to_string(), parse::help_examples("", &top))];
    for sub in &subcommands {
        let text = help(&[sub, "--help"]);
        // A command with subcommands of its own (`hdw export fmu`): each of those ends with
        // the worked example.
        let nested = listed(&text);
        let pages: Vec<(String, String)> = if nested.is_empty() {
            vec![(sub.clone(), text)]
        } else {
            nested.iter().map(|n| (format!("{sub} {n}"), help(&[sub, n, "--help"]))).collect()
        };
        for (name, text) in pages {
            let ex = parse::help_examples(&name, &text);
            if ex.is_empty() {
                tally.failures.push(format!("hdw {name} --help has no worked example"));
            }
            all.push((name, ex));
        }
    }
    // One folder for all, in the order `hdw --help` lists the subcommands, as a user going
    // through the help pages would: later pages use what earlier ones wrote (explore and plot
    // read the study's results).
    let (dir, path) = workdir("help");
    for (_, examples) in &all {
        run_all(examples, &dir, &path, &mut tally);
    }
    let _ = std::fs::remove_dir_all(&dir);
    report("help-examples-summary", &tally);
}

#[test]
fn every_shipped_study_is_in_the_studies_table() {
    let readme = std::fs::read_to_string(repo_path("studies/README.md")).unwrap();
    let mut missing = Vec::new();
    for e in std::fs::read_dir(repo_path("studies")).unwrap().flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        if name.ends_with(".toml") && !readme.contains(&format!("| `{name}` |")) {
            missing.push(name);
        }
    }
    assert!(missing.is_empty(), "studies/README.md's table lacks {missing:?}");
}
