//! The `hiperface` command.

use clap::{Parser, Subcommand};
use hiperface_conformance::{demo, profile_file};
use hiperface_model::command::COMMAND_TABLE;
use std::process::ExitCode;

#[derive(Parser)]
#[command(name = "hiperface", version, about = "HIPERFACE reference model and conformance suite")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
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
    /// Print a profile as TOML, to start a data sheet of your own.
    ExportProfile { profile: String },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
        Command::Demo { profile } => match profile_file::resolve(&profile) {
            Ok(p) => {
                print!("{}", demo::run(p));
                ExitCode::SUCCESS
            }
            Err(e) => fail(e),
        },
        Command::Profiles => {
            for (name, make) in hiperface_model::profiles::BUILTIN {
                let p = make();
                println!("{name:<16} {:?} edition, type {:02X}h, range {} steps", p.edition, p.type_code, p.range());
            }
            ExitCode::SUCCESS
        }
        Command::CheckProfile { profile } => match profile_file::resolve(&profile) {
            Ok(p) => {
                println!(
                    "{}: valid ({:?} edition, {} commands, range {} steps)",
                    p.name,
                    p.edition,
                    p.commands.iter().count(),
                    p.range()
                );
                ExitCode::SUCCESS
            }
            Err(e) => fail(e),
        },
        Command::ExportProfile { profile } => match profile_file::resolve(&profile) {
            Ok(p) => {
                print!("{}", profile_file::to_toml(&p));
                ExitCode::SUCCESS
            }
            Err(e) => fail(e),
        },
        Command::Commands => {
            println!("{:<6} {:<50} {:>8}  master  slave", "cmd", "name", "max ms");
            for s in COMMAND_TABLE {
                let ms = s.max_response_ms.map_or("-".to_string(), |m| m.to_string());
                println!("{:02X}h    {:<50} {:>8}  {:?}  {:?}", s.id.byte(), s.name, ms, s.master_data, s.slave_data);
            }
            ExitCode::SUCCESS
        }
    }
}

fn fail(e: impl std::fmt::Display) -> ExitCode {
    eprintln!("error: {e}");
    ExitCode::from(2)
}
