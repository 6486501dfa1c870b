//! `catalogue-mutants`: the catalogue measured against defective devices (see the
//! crate's documentation and the book's verification chapter).

use clap::{Parser, Subcommand};
use hiperface_mutants::families::{self, Certifier};
use hiperface_mutants::run::{self, Family, Outcome, WorkerLine};
use hiperface_mutants::survivors::{self, Survivors};
use std::collections::BTreeSet;
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::{Duration, Instant};

#[derive(Parser)]
#[command(name = "catalogue-mutants", about = "The catalogue measured against defective encoders and masters")]
struct Cli {
    #[command(subcommand)]
    command: Cmd,
}

#[derive(Subcommand)]
enum Cmd {
    /// List a family's mutants: id and key.
    List {
        #[arg(long, default_value = "encoder")]
        family: String,
    },
    /// Certify mutants, print the table, compare with the list of survivors (exit 1 on
    /// a difference).
    Run {
        /// Families to run (encoder, wire, master); all without.
        #[arg(long = "family")]
        families: Vec<String>,
        /// Worker processes.
        #[arg(long, default_value_t = 2)]
        jobs: usize,
        /// A mutant with no result after this many seconds is hung.
        #[arg(long, default_value_t = 20)]
        timeout_s: u64,
        /// Every n-th mutant of each family only (a sample: listed survivors not run are
        /// not stale).
        #[arg(long)]
        every: Option<usize>,
        /// Only these ids (comma-separated), of one family.
        #[arg(long)]
        ids: Option<String>,
        /// The list of survivors.
        #[arg(long, default_value = "mutants/survivors.toml")]
        list: PathBuf,
        /// Where each family's results go, one JSON line per mutant.
        #[arg(long, default_value = "target/catalogue-mutants")]
        out: PathBuf,
        /// Print every mutant's result as it comes.
        #[arg(long)]
        verbose: bool,
    },
    /// Run encoder mutants beside the conformant device on random streams of requests:
    /// a witness of a difference at the wire, or none.
    Diff {
        /// Encoder mutant ids (comma-separated); 0 checks the method (no difference).
        #[arg(long)]
        ids: String,
        #[arg(long, default_value_t = 2000)]
        streams: u64,
        #[arg(long, default_value_t = 40)]
        frames: usize,
    },
    /// Compare the mutants compiled in with `cargo mutants --list` of the same files:
    /// every one it makes is compiled in or listed as skipped (with why), and every one
    /// compiled in is one it makes (exit 1 otherwise).
    CrossCheck {
        /// Its JSON list, made beforehand (`cargo mutants --list --json --no-config`);
        /// without, cargo-mutants is run here.
        #[arg(long)]
        list: Option<PathBuf>,
    },
    /// Certify the conformant device (no mutant) in every configuration: each must PASS.
    Baseline,
    /// Certify mutants in this process, one JSON line each (the workers of `run`).
    #[command(hide = true)]
    Worker {
        #[arg(long)]
        family: String,
        #[arg(long)]
        ids: String,
    },
}

/// How many random streams of how many requests a surviving encoder mutant is run on
/// beside the conformant device (`diff`).
const DIFF_STREAMS: u64 = 1500;
const DIFF_FRAMES: usize = 40;

fn family(name: &str) -> Result<Family, String> {
    Family::parse(name).ok_or_else(|| format!("no family `{name}` (encoder, wire, master)"))
}

fn ids(text: &str) -> Result<Vec<u32>, String> {
    text.split(',')
        .filter(|s| !s.is_empty())
        .map(|s| s.trim().parse().map_err(|_| format!("not an id: `{s}`")))
        .collect()
}

fn main() -> ExitCode {
    // A mutant's panic is the device's crash, noted by the device: not printed.
    std::panic::set_hook(Box::new(|info| {
        if std::env::var_os("CATALOGUE_MUTANTS_PANICS").is_some() {
            eprintln!("{info}");
        }
    }));
    let cli = Cli::parse();
    let result = match cli.command {
        Cmd::List { family: f } => family(&f).map(|f| {
            for n in families::names(f) {
                println!("{:5} {}", n.id, n.key);
            }
            ExitCode::SUCCESS
        }),
        Cmd::Diff { ids: list, streams, frames } => ids(&list).map(|ids| {
            for id in ids {
                let t = Instant::now();
                match hiperface_mutants::diff::search(id, streams, frames) {
                    Some(w) => println!("{id}: {w}"),
                    None => println!(
                        "{id}: no difference in {streams} streams of {frames} requests ({:.1} s)",
                        t.elapsed().as_secs_f64()
                    ),
                }
            }
            ExitCode::SUCCESS
        }),
        Cmd::CrossCheck { list } => hiperface_mutants::cross_check::run(list.as_deref()),
        Cmd::Baseline => {
            let mut b = hiperface_mutants::source::Baselines::new();
            let mut bad = b.not_passed();
            bad.extend(
                hiperface_mutants::wire::Baselines::new().not_passed().into_iter().map(|c| format!("wire device: {c}")),
            );
            bad.extend(
                hiperface_mutants::master::Baselines::new().not_passed().into_iter().map(|c| format!("master: {c}")),
            );
            for c in &bad {
                println!("not PASSED: {c}");
            }
            Ok(if bad.is_empty() { ExitCode::SUCCESS } else { ExitCode::FAILURE })
        }
        Cmd::Worker { family: f, ids: list } => family(&f).and_then(|f| {
            let ids = ids(&list)?;
            let mut certifier = Certifier::new(f);
            let mut out = std::io::stdout().lock();
            for id in ids {
                let t = Instant::now();
                let verdicts = certifier.certify(id);
                let witness = (f == Family::Encoder && !survivors::told(verdicts.caught))
                    .then(|| hiperface_mutants::diff::search(id, DIFF_STREAMS, DIFF_FRAMES))
                    .flatten()
                    .map(|w| w.to_string());
                let line = WorkerLine { id, verdicts, witness, ms: t.elapsed().as_secs_f64() * 1000.0 };
                let text = serde_json::to_string(&line).map_err(|e| e.to_string())?;
                writeln!(out, "{text}").and_then(|_| out.flush()).map_err(|e| e.to_string())?;
            }
            Ok(ExitCode::SUCCESS)
        }),
        Cmd::Run { families: fs, jobs, timeout_s, every, ids: only, list, out, verbose } => {
            run_families(fs, jobs, Duration::from_secs(timeout_s), every, only, &list, &out, verbose)
        }
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("catalogue-mutants: {e}");
            ExitCode::from(2)
        }
    }
}

#[allow(clippy::too_many_arguments)]
fn run_families(
    names: Vec<String>,
    jobs: usize,
    timeout: Duration,
    every: Option<usize>,
    only: Option<String>,
    list: &PathBuf,
    out: &PathBuf,
    verbose: bool,
) -> Result<ExitCode, String> {
    let fams: Vec<Family> = if names.is_empty() {
        Family::ALL.to_vec()
    } else {
        names.iter().map(|n| family(n)).collect::<Result<_, _>>()?
    };
    let text = std::fs::read_to_string(list).map_err(|e| format!("{}: {e}", list.display()))?;
    let listed = Survivors::parse(&text).map_err(|e| format!("{}: {e}", list.display()))?;
    let only: Option<BTreeSet<u32>> = only.as_deref().map(ids).transpose()?.map(|v| v.into_iter().collect());
    std::fs::create_dir_all(out).map_err(|e| format!("{}: {e}", out.display()))?;
    let mut differences = String::new();
    let mut rows = Vec::new();
    for fam in fams {
        let all = families::names(fam);
        let chosen: Vec<_> = all
            .iter()
            .enumerate()
            .filter(|(i, n)| every.is_none_or(|e| i % e.max(1) == 0) && only.as_ref().is_none_or(|o| o.contains(&n.id)))
            .map(|(_, n)| n.clone())
            .collect();
        let complete = chosen.len() == all.len();
        let reached = hiperface_mutants::source::reached_of(fam);
        let started = Instant::now();
        let ids: Vec<u32> = chosen.iter().map(|n| n.id).collect();
        eprintln!("{}: {} mutants on {jobs} workers", fam.name(), ids.len());
        let results = run::certify_all(fam, &ids, jobs, timeout, |done, total, id, line: &WorkerLine| {
            if verbose {
                eprintln!(
                    "[{done}/{total}] {id} {} {:.1} ms {}",
                    line.verdicts.caught.label(),
                    line.ms,
                    line.verdicts.finding.as_deref().unwrap_or("")
                );
            } else if done % 100 == 0 || done == total {
                eprintln!("{}: {done}/{total}", fam.name());
            }
        })
        .map_err(|e| format!("starting the workers: {e}"))?;
        let wall = started.elapsed();
        let outcomes: Vec<Outcome> = chosen
            .iter()
            .filter_map(|n| {
                let r = results.get(&n.id)?;
                Some(Outcome {
                    name: n.clone(),
                    verdicts: r.verdicts.clone(),
                    reached: reached.as_ref().map(|set| set.contains(&n.id)),
                    witness: r.witness.clone(),
                    ms: r.ms,
                })
            })
            .collect();
        // A part of a family (`--ids`, `--every`) does not replace the whole one's results.
        let path = out.join(format!("{}{}.jsonl", fam.name(), if complete { "" } else { "-part" }));
        let mut file = std::fs::File::create(&path).map_err(|e| format!("{}: {e}", path.display()))?;
        for o in &outcomes {
            let line = serde_json::to_string(o).map_err(|e| e.to_string())?;
            writeln!(file, "{line}").map_err(|e| format!("{}: {e}", path.display()))?;
        }
        let table = survivors::table(fam, &outcomes, &listed, complete);
        let times: Vec<f64> = outcomes.iter().map(|o| o.ms).collect();
        let mean = times.iter().sum::<f64>() / times.len().max(1) as f64;
        let max = times.iter().copied().fold(0.0, f64::max);
        eprintln!(
            "{}: {} mutants in {:.1} s on {jobs} workers; per mutant {mean:.1} ms mean, {max:.1} ms at most; results in {}",
            fam.name(),
            outcomes.len(),
            wall.as_secs_f64(),
            path.display()
        );
        differences.push_str(&survivors::differences(fam, &table));
        rows.push(table.row(fam));
    }
    println!("{}", survivors::Table::HEADER);
    for r in rows {
        println!("{r}");
    }
    if differences.is_empty() {
        println!("every survivor listed, every listed one let through");
        Ok(ExitCode::SUCCESS)
    } else {
        print!("{differences}");
        println!("the run differs from {}: take it up in the list (or close the hole)", list.display());
        Ok(ExitCode::FAILURE)
    }
}
