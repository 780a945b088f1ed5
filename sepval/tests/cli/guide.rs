//! The examples of the user guide (docs/guide.md) and of the README's tour, checked: every
//! `sepval ...` line of their `sh` blocks is parsed by the command line's own parser
//! (`sepval_cli::Cli`), so an example with a wrong flag or value fails here; the cheap ones
//! (`effects`, `scenario`, `simulate`, `goals`) are run in order in one temporary directory,
//! each whose inputs an earlier example wrote or the repository holds.

use std::path::{Path, PathBuf};

use clap::Parser;
use sepval_cli::Cli;
use sepval_tests::{ok, sepval};

/// The commands cheap enough to run here (a second or less each).
const CHEAP: [&str; 4] = ["effects", "scenario", "simulate", "goals"];
/// The flags whose value is a file the command reads.
const INPUT_FLAGS: [&str; 10] = [
    "--scenario",
    "--from-daveml",
    "--from-shape",
    "--map",
    "--factors",
    "--extension",
    "--data",
    "--sim",
    "--aircraft",
    "--store-shape",
];

fn repository() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// One example: the page and line it starts on, and its words (`sepval` first).
struct Example {
    at: String,
    words: Vec<String>,
}

/// Every `sepval ...` command of the `sh` blocks of `page` (relative to the repository):
/// continuation lines joined, comments dropped, `a && b` split, a path to the binary
/// (`./target/release/sepval`) read as `sepval`.
fn examples(page: &str) -> Vec<Example> {
    let text = std::fs::read_to_string(repository().join(page)).expect("read the page");
    let mut found = Vec::new();
    let (mut in_sh, mut pending, mut start) = (false, String::new(), 0);
    for (i, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.starts_with("```") {
            in_sh = !in_sh && line == "```sh";
            continue;
        }
        if !in_sh {
            continue;
        }
        if pending.is_empty() {
            start = i + 1;
        }
        let code = line.split(" #").next().unwrap_or("");
        let code = if code.starts_with('#') { "" } else { code };
        if let Some(head) = code.strip_suffix('\\') {
            pending.push_str(head);
            pending.push(' ');
            continue;
        }
        pending.push_str(code);
        for part in std::mem::take(&mut pending).split("&&") {
            let words: Vec<String> = part.split_whitespace().map(str::to_string).collect();
            let is_sepval = words
                .first()
                .is_some_and(|w| w == "sepval" || w.ends_with("/sepval"));
            if is_sepval {
                let mut words = words;
                words[0] = "sepval".into();
                found.push(Example {
                    at: format!("{page}:{start}"),
                    words,
                });
            }
        }
    }
    found
}

#[test]
fn guide_examples_parse_and_the_cheap_ones_run() {
    let mut all = examples("docs/guide.md");
    let guide = all.len();
    all.extend(examples("README.md"));
    assert!(guide >= 20, "only {guide} examples found in docs/guide.md");
    for example in &all {
        if let Err(e) = Cli::try_parse_from(&example.words) {
            panic!(
                "{}: `{}` does not parse:\n{e}",
                example.at,
                example.words.join(" ")
            );
        }
    }
    let dir = tempfile::tempdir().unwrap();
    let (mut ran, mut skipped) = (Vec::new(), Vec::new());
    for example in all.iter().filter(|e| CHEAP.contains(&e.words[1].as_str())) {
        let Some(args) = runnable(&example.words[1..], dir.path()) else {
            skipped.push(example.at.clone());
            continue;
        };
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let out = sepval(&args, dir.path());
        ok(&out);
        if let Some(i) = args.iter().position(|a| *a == "--out") {
            let written = dir.path().join(args[i + 1]);
            assert!(
                written.exists(),
                "{}: wrote no {}",
                example.at,
                written.display()
            );
        }
        ran.push(example.at.clone());
    }
    eprintln!("guide: ran {ran:?}; inputs not at hand, parsed only: {skipped:?}");
    for command in CHEAP {
        assert!(
            all.iter()
                .any(|e| e.words[1] == command && ran.contains(&e.at)),
            "no example of `sepval {command}` ran"
        );
    }
}

/// The arguments of `words` (without `sepval`) to run in `dir`, an input the repository holds
/// given by its absolute path; `None` when an input is neither in `dir` nor in the repository.
fn runnable(words: &[String], dir: &Path) -> Option<Vec<String>> {
    let mut args = Vec::with_capacity(words.len());
    let mut input = false;
    for word in words {
        let mut arg = word.clone();
        if input && !matches!(word.as_str(), "truth" | "nominal") && !dir.join(word).exists() {
            let held = repository().join(word);
            if !held.exists() {
                return None;
            }
            arg = held.to_string_lossy().into_owned();
        }
        input = INPUT_FLAGS.contains(&word.as_str());
        args.push(arg);
    }
    Some(args)
}
