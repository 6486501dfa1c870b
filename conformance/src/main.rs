//! The `hiperface` command: the subcommands and what each calls. The arguments of the
//! three front ends and their run policy are in the library, where tests reach them
//! (`slave::cli`, `master::cli`, `listen::cli`, `listen::monitor`), the flags they
//! share in `args`; the small commands (profiles, vectors, clauses) are here.
//!
//! Long because: it is the command's table of subcommands, an arm each; the front ends'
//! own arguments are in their cli.rs already, the shared flags in args.rs.

use clap::{CommandFactory, Parser, Subcommand, ValueEnum};
use hiperface_conformance::args::WorldArgs;
use hiperface_conformance::command::{CommandError, Ended};
use hiperface_conformance::port::PortSpec;
use hiperface_conformance::say;
use hiperface_conformance::{demo, line, master, simulate, slave};
use hiperface_model::command::{DataLength, COMMAND_TABLE};
use hiperface_suite::profile_file;
use hiperface_suite::world::World;
use serialport::SerialPort as _;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(name = "hiperface", version, about = "HIPERFACE reference model and conformance suite")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Certify a device under test.
    Certify {
        #[command(subcommand)]
        what: CertifyWhat,
    },
    /// Serve the reference model as a virtual encoder on a port or a new pseudo-terminal.
    Simulate {
        /// `pty` for a new pseudo-terminal pair (its path is printed), or a serial port
        /// path.
        #[arg(long, default_value = "pty")]
        port: PortSpec,
        #[arg(long, default_value = "SRS50")]
        profile: String,
        /// Log every frame to standard error.
        #[arg(long)]
        log: bool,
        #[command(flatten)]
        world: WorldArgs,
    },
    /// Run a demonstration session against the reference slave in virtual time.
    Demo {
        /// A built-in profile name or a profile TOML file.
        #[arg(long, default_value = "SRS50")]
        profile: String,
    },
    /// List the built-in profiles.
    Profiles,
    /// Load and validate a profile (built-in name or TOML file).
    CheckProfile { profile: String },
    /// Print the command table (000 Table 10 and legacy 63h).
    Commands,
    /// Golden vectors: generate, verify, export, the protocol reference (book).
    Vectors {
        #[command(subcommand)]
        what: VectorsCommand,
    },
    /// Print a profile as TOML, to start a data sheet of your own.
    ExportProfile { profile: String },
    /// The reference master: start-up, cyclic Read Position, fault reaction (000:3.3).
    Master(master::cli::MasterArgs),
    /// Grade a capture of a bus (a wire log, a logic analyzer's CSV, sigrok-cli's UART
    /// decoder output) without talking: both sides; exit 1 on a FAIL, 3 when nothing
    /// could be graded. A certify report is played back from the record of its wire:
    /// the run's verdicts graded again and its exit code (0, 1, 3); 4 when the report
    /// does not state what its record gives, 5 when its signature does not hold
    /// (`--verify`).
    Decode(hiperface_conformance::listen::cli::DecodeArgs),
    /// Certify reports side by side: a matrix of cases (or scenarios) by report, in
    /// Markdown, HTML, JSON and JUnit; with `--baseline`, exit 1 when a report regressed
    /// against it.
    Compare(hiperface_conformance::report::compare::CompareArgs),
    /// Make an Ed25519 key pair to sign certificates with (`certify … --sign KEY`): the
    /// private key at FILE (readable by you alone, never over an existing file), the
    /// public key at FILE.pub, which a lab publishes and `decode --verify` takes.
    Keygen {
        #[arg(long, value_name = "FILE")]
        out: PathBuf,
    },
    /// Listen to a live bus without talking (the port is opened read-only) and grade
    /// both sides as it goes; Ctrl-C ends the run with a summary and the reports.
    Monitor(hiperface_conformance::listen::monitor::MonitorArgs),
    /// Clause coverage: what cites each clause of the registry (exit 1 when a
    /// normative clause is neither covered nor listed as unobservable).
    Clauses {
        /// Only the normative clauses nothing covers.
        #[arg(long)]
        uncovered: bool,
        #[arg(long, value_enum, default_value = "markdown")]
        format: TextFormat,
    },
    /// Shell completions on standard output, e.g. `hiperface completions bash >
    /// ~/.local/share/bash-completion/completions/hiperface`.
    Completions {
        #[arg(value_enum)]
        shell: clap_complete::Shell,
    },
    /// Manual pages (roff): hiperface(1) on standard output, or a page per command
    /// (hiperface-certify-slave.1, ...) written into DIR with `--out DIR`.
    Man {
        /// Write a page per command into this directory (made if need be) instead.
        #[arg(long, value_name = "DIR")]
        out: Option<PathBuf>,
    },
}

/// How `vectors show` writes its piece.
#[derive(Clone, Copy, ValueEnum)]
enum PieceFormat {
    #[value(alias = "md")]
    Markdown,
    Html,
    Svg,
}

/// A table for people or for programs (`clauses`, `vectors export`).
#[derive(Clone, Copy, ValueEnum)]
enum TextFormat {
    // `md`: the old name of `clauses --format markdown`, kept for one release.
    #[value(alias = "md")]
    Markdown,
    Json,
}

#[derive(Subcommand)]
enum CertifyWhat {
    /// Act as master against a slave (encoder).
    Slave(slave::cli::CertifySlaveArgs),
    /// Act as encoder against a master (a drive): scenarios with injected faults.
    Master(master::cli::CertifyMasterArgs),
}

#[derive(Subcommand)]
enum VectorsCommand {
    /// Every id `vectors show` takes: the examples' (with their command, what each
    /// shows and its file) and the timing diagrams' (with their titles).
    List {
        /// The folder of the vector files (default: the files built into the command).
        #[arg(long)]
        dir: Option<PathBuf>,
    },
    /// Write the generated vector files into DIR (documents.json and master-tables.json
    /// are transcribed from the documents by hand and never generated).
    Generate {
        #[arg(default_value = "vectors")]
        dir: PathBuf,
    },
    /// Re-check every vector file in DIR: schema, checksums, agreement with the model.
    Verify {
        #[arg(default_value = "vectors")]
        dir: PathBuf,
    },
    /// Write documentation tables (one per command) from the vector files in DIR.
    Export {
        #[arg(long, value_enum, default_value = "markdown")]
        format: TextFormat,
        /// Write vectors.md / vectors-tables.json here instead of standard output.
        #[arg(long)]
        out: Option<PathBuf>,
        #[arg(default_value = "vectors")]
        dir: PathBuf,
    },
    /// One example or diagram of the protocol reference on its own, for a manual of your
    /// own: a vector's example by its id (Markdown, or --format html), a timing diagram by
    /// its id (SVG, or --format markdown or html).
    Show {
        /// A vector's id (001-5.1.4.1-read-position) or a diagram's (exchange-42h).
        id: String,
        /// Markdown or HTML for an example; SVG (its own), Markdown or HTML for a diagram.
        /// An example's Markdown carries no style: its `hf-*` classes are styled by
        /// frames.css, which `vectors book` writes beside the pages; HTML carries it.
        #[arg(long, value_enum)]
        format: Option<PieceFormat>,
        /// The folder of the vector files (default: the files built into the command).
        #[arg(long)]
        dir: Option<PathBuf>,
    },
    /// Write the protocol reference (a Markdown chapter per command, every frame a byte
    /// diagram from a vector, timing diagrams as SVG, the diagrams' style sheet
    /// frames.css) into DIR, e.g. `--out docs/src/reference` for the user guide.
    Book {
        /// The folder to write the pages into (made if need be).
        #[arg(long, value_name = "DIR")]
        out: PathBuf,
        /// The folder of the vector files (default: the files built into the command).
        #[arg(long)]
        dir: Option<PathBuf>,
    },
}

/// `hiperface clauses`: exit 1 when a normative clause is neither covered nor listed.
fn print_clauses(uncovered: bool, format: TextFormat) -> Result<Ended, CommandError> {
    use hiperface_conformance::clauses;
    let all = clauses::coverage()?;
    let rows: Vec<&clauses::ClauseCoverage> = all.iter().filter(|c| !uncovered || c.uncovered()).collect();
    let text = match format {
        TextFormat::Markdown => clauses::markdown(&rows, &all),
        TextFormat::Json => serde_json::to_string_pretty(&rows).map_err(json_error)? + "\n",
    };
    print_all(&text)?;
    Ok(if all.iter().any(|c| c.uncovered()) { Ended::CheckFailed } else { Ended::Done })
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Certify { what: CertifyWhat::Master(args) } => master::cli::certify_master(&args),
        Command::Certify { what: CertifyWhat::Slave(args) } => slave::cli::certify_slave(args),
        Command::Master(args) => master::cli::reference_master(&args),
        Command::Simulate { port, profile, log, world } => run_simulator(&port, &profile, log, &world.world()),
        Command::Demo { profile } => profile_file::resolve(&profile)
            .map_err(CommandError::from)
            .and_then(|p| print_all(&demo::run(p)).map(|()| Ended::Done)),
        Command::Profiles => {
            for (name, make) in hiperface_model::profiles::BUILTIN {
                let p = make();
                say!("{name:<16} {:?} edition, type {:02X}h, range {} steps", p.edition, p.type_code, p.range());
            }
            Ok(Ended::Done)
        }
        Command::CheckProfile { profile } => profile_file::resolve(&profile).map_err(CommandError::from).map(|p| {
            say!(
                "{}: valid ({:?} edition, {} commands, range {} steps)",
                p.name,
                p.edition,
                p.commands.iter().count(),
                p.range()
            );
            Ended::Done
        }),
        Command::ExportProfile { profile } => profile_file::resolve(&profile)
            .map_err(CommandError::from)
            .and_then(|p| print_all(&profile_file::to_toml(&p)).map(|()| Ended::Done)),
        Command::Vectors { what } => vectors_command(what),
        Command::Decode(args) => hiperface_conformance::listen::cli::decode(&args),
        Command::Compare(args) => hiperface_conformance::report::compare::compare(&args),
        Command::Keygen { out } => hiperface_conformance::report::signature::generate(&out).map(|public| {
            say!("private key: {} (keep it to yourself; certify … --sign {})", out.display(), out.display());
            say!("public key:  {} (publish it; decode report.json --verify {})", public.display(), public.display());
            Ended::Done
        }),
        Command::Monitor(args) => {
            let stop = hiperface_conformance::interrupt::flag("\ninterrupted: the summary and the reports follow");
            hiperface_conformance::listen::monitor::monitor(&args, &stop)
        }
        Command::Clauses { uncovered, format } => print_clauses(uncovered, format),
        Command::Completions { shell } => {
            let mut script = Vec::new();
            clap_complete::generate(shell, &mut Cli::command(), "hiperface", &mut script);
            print_all(&String::from_utf8_lossy(&script)).map(|()| Ended::Done)
        }
        Command::Man { out } => man_pages(out.as_deref()),
        Command::Commands => {
            // 000 Table 10: the data bytes of the request and of the reply (without the
            // address, the command and the checksum), and the maximum response time.
            say!("{:<6} {:<50} {:>8}  {:>12}  {:>10}", "cmd", "name", "max ms", "request data", "reply data");
            for s in COMMAND_TABLE {
                let ms = s.max_response_ms.map_or("-".to_string(), |m| m.to_string());
                let (request, reply) = (data_length(s.master_data), data_length(s.slave_data));
                say!("{:02X}h    {:<50} {:>8}  {request:>12}  {reply:>10}", s.id.byte(), s.name, ms);
            }
            Ok(Ended::Done)
        }
    };
    // The one place an ending becomes an exit code.
    match result {
        Ok(ended) => ExitCode::from(ended.exit_code()),
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(e.exit_code())
        }
    }
}

fn run_simulator(port: &PortSpec, profile: &str, log: bool, world: &World) -> Result<Ended, CommandError> {
    let profile = profile_file::resolve(profile)?;
    let port: Box<dyn serialport::SerialPort> = match port {
        PortSpec::Pty => {
            let (sim_end, other) = hiperface_conformance::line::pty_pair()
                .map_err(|e| CommandError::Line(format!("cannot create a pseudo-terminal pair: {e}")))?;
            say!("{}", other.name().unwrap_or_default());
            // Keep the other end open so the pseudo-terminal lives until we stop.
            std::mem::forget(other);
            Box::new(sim_end)
        }
        PortSpec::Path(path) => {
            line::serial::open_port(path, profile.settings).map_err(|e| CommandError::Line(e.to_string()))?
        }
        other => {
            return Err(CommandError::Usage(format!(
                "the simulator serves a port of its own: `pty` or a serial port path, not `{other}`"
            )))
        }
    };
    let stop = hiperface_conformance::interrupt::flag("\ninterrupted: the simulator stops");
    let mut stderr = std::io::stderr();
    let log: Option<&mut dyn std::io::Write> = if log { Some(&mut stderr) } else { None };
    simulate::serve(port, profile, world, stop, log).map_err(|e| CommandError::Line(e.to_string()))?;
    Ok(Ended::Done)
}

/// The vector files of `dir`, or those built into the command.
fn vector_files(
    dir: Option<&std::path::Path>,
) -> Result<Vec<(String, hiperface_suite::vectors::VectorFile)>, CommandError> {
    match dir {
        Some(d) => hiperface_suite::vectors::load_named(d)
            .map_err(|e| CommandError::Usage(format!("--dir {}: {e}", d.display()))),
        None => Ok(hiperface_conformance::clauses::builtin_vector_files()?),
    }
}

/// Print to standard output; a reader that stops early (`| head`) is not an error.
fn print_all(text: &str) -> Result<(), CommandError> {
    use std::io::Write as _;
    match std::io::stdout().lock().write_all(text.as_bytes()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => Err(CommandError::Output(e)),
        _ => Ok(()),
    }
}

fn vectors_command(what: VectorsCommand) -> Result<Ended, CommandError> {
    use hiperface_suite::vectors;
    match what {
        VectorsCommand::Generate { dir } => {
            // documents.json and master-tables.json are written from the documents, by hand.
            for (name, file) in vectors::generate::files() {
                let json = serde_json::to_string_pretty(&file).map_err(json_error)? + "\n";
                let path = dir.join(name);
                std::fs::write(&path, json).map_err(CommandError::file(&path))?;
                say!("{}: {} vectors", path.display(), file.vectors.len());
            }
            Ok(Ended::Done)
        }
        VectorsCommand::Verify { dir } => {
            // Nothing verified is not a pass: an error of verify_dir.
            let (count, failures) = vectors::verify_dir(&dir)?;
            if failures.is_empty() {
                say!("{count} vectors verified: schema, checksums, agreement with the model");
                return Ok(Ended::Done);
            }
            for f in &failures {
                say!("FAIL {f}");
            }
            say!("{} of {count} vectors failed", failures.len());
            Ok(Ended::CheckFailed)
        }
        VectorsCommand::Export { format, out, dir } => {
            let mut files = Vec::new();
            for path in vectors::files(&dir)? {
                files.push(vectors::load(&path)?);
            }
            let (name, text) = match format {
                TextFormat::Markdown => ("vectors.md", vectors::export::markdown(&files)),
                TextFormat::Json => {
                    let json = serde_json::to_string_pretty(&vectors::export::tables(&files)).map_err(json_error)?;
                    ("vectors-tables.json", json + "\n")
                }
            };
            match out {
                Some(dir) => {
                    std::fs::create_dir_all(&dir)
                        .and_then(|()| std::fs::write(dir.join(name), text))
                        .map_err(CommandError::file(&dir))?;
                    say!("{}", dir.join(name).display());
                }
                None => print_all(&text)?,
            }
            Ok(Ended::Done)
        }
        VectorsCommand::List { dir } => {
            print_all(&vectors::reference::list(&vector_files(dir.as_deref())?))?;
            Ok(Ended::Done)
        }
        VectorsCommand::Show { id, format, dir } => {
            let files = vector_files(dir.as_deref())?;
            let format = format.map(|f| match f {
                PieceFormat::Markdown => vectors::reference::PieceFormat::Markdown,
                PieceFormat::Html => vectors::reference::PieceFormat::Html,
                PieceFormat::Svg => vectors::reference::PieceFormat::Svg,
            });
            let text =
                vectors::reference::piece(&files, &id, format).map_err(|e| CommandError::Usage(e.to_string()))?;
            print_all(&text)?;
            Ok(Ended::Done)
        }
        VectorsCommand::Book { out, dir } => {
            let files = vector_files(dir.as_deref())?;
            let pages = vectors::reference::book(&files);
            for (name, text) in &pages {
                let path = out.join(name);
                if let Some(parent) = path.parent() {
                    std::fs::create_dir_all(parent).map_err(CommandError::file(parent))?;
                }
                std::fs::write(&path, text).map_err(CommandError::file(&path))?;
            }
            let svg = pages.iter().filter(|(n, _)| n.ends_with(".svg")).count();
            say!(
                "{}: {} pages (the index, a chapter per command, timing, error codes, editions, master-side tables) and {svg} diagrams",
                out.display(),
                pages.len() - svg
            );
            // A page this run did not write is left alone, but named: the reference's
            // test fails on it.
            let written: Vec<&str> = pages.iter().map(|(n, _)| n.as_str()).collect();
            let mut others = Vec::new();
            for sub in ["", "svg"] {
                let Ok(entries) = std::fs::read_dir(out.join(sub)) else { continue };
                others.extend(
                    entries
                        .filter_map(|e| e.ok().map(|e| e.file_name().to_string_lossy().into_owned()))
                        .filter(|n| n.ends_with(".md") || n.ends_with(".svg"))
                        .map(|n| if sub.is_empty() { n } else { format!("{sub}/{n}") })
                        .filter(|n| !written.contains(&n.as_str())),
                );
            }
            others.sort();
            for name in others {
                say!("{}: not written by this run (a page of an earlier one? remove it)", out.join(name).display());
            }
            Ok(Ended::Done)
        }
    }
}

/// The manual: hiperface(1) on standard output, or into `out` a page per command and
/// subcommand, each named as `man` finds it (hiperface-certify-slave.1).
fn man_pages(out: Option<&std::path::Path>) -> Result<Ended, CommandError> {
    let render = |c: clap::Command| -> Result<Vec<u8>, CommandError> {
        let mut page = Vec::new();
        clap_mangen::Man::new(c).render(&mut page).map_err(CommandError::Output)?;
        Ok(page)
    };
    let top = Cli::command();
    let Some(dir) = out else {
        // On its own the page names pages (hiperface-certify(1), ...) that only `--out`
        // writes: it says so, and how to read them.
        let mut page = String::from_utf8_lossy(&render(top)?).into_owned();
        page.push_str(
            ".SH FILES\nThe page of each command named above (hiperface\\-certify(1), \
             hiperface\\-certify\\-slave(1), ...) is written by \\fBhiperface man \\-\\-out\\fR \\fIDIR\\fR; \
             read one with \\fBman \\-l\\fR \\fIDIR\\fR\\fB/hiperface\\-certify\\-slave.1\\fR, or put \\fIDIR\\fR on \
             \\fBMANPATH\\fR (as man1).\n",
        );
        return print_all(&page).map(|()| Ended::Done);
    };
    std::fs::create_dir_all(dir).map_err(CommandError::file(dir))?;
    let mut pages = vec![("hiperface".to_string(), top.clone())];
    for sub in top.get_subcommands().filter(|s| s.get_name() != "help") {
        let name = format!("hiperface-{}", sub.get_name());
        for nested in sub.get_subcommands().filter(|s| s.get_name() != "help") {
            let nested_name = format!("{name}-{}", nested.get_name());
            pages.push((nested_name.clone(), nested.clone().name(nested_name)));
        }
        pages.push((name.clone(), sub.clone().name(name)));
    }
    for (name, command) in pages {
        let path = dir.join(format!("{name}.1"));
        std::fs::write(&path, render(command)?).map_err(CommandError::file(&path))?;
        say!("{}", path.display());
    }
    Ok(Ended::Done)
}

/// A data length of 000 Table 10 as people read it: "2", "4-131", "no frame".
fn data_length(d: DataLength) -> String {
    match d {
        DataLength::Fixed(n) => n.to_string(),
        DataLength::Range { min, max } => format!("{min}-{max}"),
        DataLength::NoFrame => "no frame".into(),
    }
}

/// A report or table that does not serialise: the command's own fault, said as such.
fn json_error(e: serde_json::Error) -> CommandError {
    CommandError::Output(std::io::Error::other(e))
}
