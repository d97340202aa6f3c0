//! Every option of every command says what it does (issue 20, defect 13: several had no
//! `--help` text).

use clap::CommandFactory;

fn missing(cmd: &clap::Command, path: &str, out: &mut Vec<String>) {
    for arg in cmd.get_arguments() {
        let id = arg.get_id().as_str();
        if id == "help" || id == "version" {
            continue;
        }
        if arg.get_help().is_none() && arg.get_long_help().is_none() {
            out.push(format!("{path} --{}", arg.get_long().unwrap_or(id)));
        }
    }
    for sub in cmd.get_subcommands() {
        missing(sub, &format!("{path} {}", sub.get_name()), out);
    }
}

#[test]
fn every_option_has_help_text() {
    let mut out = Vec::new();
    missing(&ocular::cli::Cli::command(), "ocular", &mut out);
    assert!(out.is_empty(), "options without --help text: {out:?}");
}
