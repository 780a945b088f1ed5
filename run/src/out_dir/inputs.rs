//! The inputs of a run, kept apart from its output directory: an `--out` that is, holds or lies
//! inside an input directory (`--from`, the run directory of `--resume`), or that holds an
//! input file, is refused whatever the flags, since a run that clears or writes its directory
//! would destroy what it reads. Paths are compared resolved: symbolic links and `..` followed
//! as far as the path exists (the output directory usually does not yet), the rest taken as
//! written.

use std::path::{Component, Path, PathBuf};

use super::error::OutDirError;
use crate::inputs::InputsRecord;

/// Something a run reads, as the flag that gives it names it.
#[derive(Debug, Clone)]
pub struct Input {
    /// The input in words, e.g. `--from DG` or `--data a.csv`.
    what: String,
    /// Its path.
    path: PathBuf,
    /// A directory (the output may be neither it nor inside it nor hold it), or a file (the
    /// output may not hold it).
    directory: bool,
}

impl Input {
    /// An input file given by `flag` (e.g. `--data`).
    pub fn file(flag: &str, path: &Path) -> Input {
        Input {
            what: format!("{flag} {}", path.display()),
            path: path.to_path_buf(),
            directory: false,
        }
    }

    /// The input files given by `flag` (none, one or several).
    pub fn files<'a>(flag: &str, paths: impl IntoIterator<Item = &'a PathBuf>) -> Vec<Input> {
        paths.into_iter().map(|p| Input::file(flag, p)).collect()
    }

    /// An input directory given by `flag` (e.g. `--from`).
    pub fn directory(flag: &str, path: &Path) -> Input {
        Input {
            what: format!("{flag} {}", path.display()),
            path: path.to_path_buf(),
            directory: true,
        }
    }

    /// An input file that another input records (e.g. the releases a `--from` directory was
    /// fitted to): `whose` names the record.
    pub fn recorded(whose: &str, path: &Path) -> Input {
        Input {
            what: format!("{} (recorded by {whose})", path.display()),
            path: path.to_path_buf(),
            directory: false,
        }
    }

    /// An input file that another input names (e.g. a table file a scenario reads): `whose`
    /// names that input.
    pub fn named_by(whose: &str, path: &Path) -> Input {
        Input {
            what: format!("the table {} that {whose} names", path.display()),
            path: path.to_path_buf(),
            directory: false,
        }
    }

    /// The input directory `path`, the run directory of the checkpoint `--resume` gives.
    pub fn resumed_run(checkpoint: &Path, path: &Path) -> Input {
        Input {
            what: format!(
                "the run directory {} of --resume {}",
                path.display(),
                checkpoint.display()
            ),
            path: path.to_path_buf(),
            directory: true,
        }
    }
}

/// What a `--from` directory records a run read (the releases, scenario and extension of its
/// record, and the releases it held out), with the directory itself: a run from it may not
/// write where they are.
pub fn recorded_inputs(from: &Path, record: &InputsRecord, held_out: &[PathBuf]) -> Vec<Input> {
    let whose = format!("--from {}", from.display());
    let mut out = vec![Input::directory("--from", from)];
    let files = record
        .data
        .iter()
        .chain(&record.scenario)
        .chain(&record.extension)
        .chain(held_out);
    out.extend(files.map(|p| Input::recorded(&whose, p)));
    out
}

/// `path` resolved: absolute, symbolic links and `..` resolved as far as it exists, the rest
/// taken lexically.
pub(super) fn resolved(path: &Path) -> PathBuf {
    let absolute = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
    let mut out = PathBuf::new();
    // How many names at the end of `out` do not exist (taken as written).
    let mut missing = 0usize;
    for c in absolute.components() {
        match c {
            Component::CurDir => {}
            // `out` has no symbolic link in it (resolved, or made of names that do not exist),
            // so its parent is `..`.
            Component::ParentDir => {
                out.pop();
                missing = missing.saturating_sub(1);
            }
            other => {
                out.push(other);
                if missing > 0 {
                    missing += 1;
                } else {
                    match std::fs::canonicalize(&out) {
                        Ok(c) => out = c,
                        Err(_) => missing = 1,
                    }
                }
            }
        }
    }
    out
}

/// Refuses an output directory `out` that is, holds or lies inside one of `inputs` (`allowed`
/// aside: the run directory a resumed run goes on in, and its checkpoint).
pub(super) fn check(out: &Path, inputs: &[Input], allowed: &[PathBuf]) -> Result<(), OutDirError> {
    let here = resolved(out);
    for input in inputs {
        let at = resolved(&input.path);
        if allowed.contains(&at) {
            continue;
        }
        let relation = if at == here {
            Some("is")
        } else if at.starts_with(&here) {
            Some("holds")
        } else if input.directory && here.starts_with(&at) {
            Some("lies inside")
        } else {
            None
        };
        if let Some(relation) = relation {
            return Err(OutDirError::IsInput {
                path: out.to_path_buf(),
                relation,
                input: input.what.clone(),
            });
        }
    }
    Ok(())
}

/// Refuses an output file `out` that is one of `inputs`: the same path once resolved, or the
/// same file by another name (a hard link).
pub fn check_file(out: &Path, inputs: &[Input]) -> Result<(), OutDirError> {
    if out.is_dir() {
        return Err(OutDirError::FileIsDirectory {
            path: out.to_path_buf(),
        });
    }
    let here = resolved(out);
    let here_id = file_id(out);
    for input in inputs {
        let same_path = resolved(&input.path) == here;
        let same_file = here_id.is_some() && file_id(&input.path) == here_id;
        if same_path || same_file {
            return Err(OutDirError::FileIsInput {
                path: out.to_path_buf(),
                input: input.what.clone(),
            });
        }
    }
    Ok(())
}

/// The device and inode of the file at `path`, when it exists (unix); none elsewhere, where
/// the resolved paths alone are compared.
fn file_id(path: &Path) -> Option<(u64, u64)> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        std::fs::metadata(path).ok().map(|m| (m.dev(), m.ino()))
    }
    #[cfg(not(unix))]
    {
        let _ = path;
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_output_is_refused_when_it_is_holds_or_lies_inside_an_input() {
        let tmp = tempfile::tempdir().unwrap();
        let d = tmp.path();
        std::fs::create_dir_all(d.join("dg/figures")).unwrap();
        std::fs::write(d.join("dg/diagnosis.json"), "{}").unwrap();
        std::fs::write(d.join("a.csv"), "").unwrap();
        std::os::unix::fs::symlink(d.join("dg"), d.join("link")).unwrap();
        let from = [Input::directory("--from", &d.join("dg"))];
        let refused =
            |out: &Path, inputs: &[Input]| check(out, inputs, &[]).err().map(|e| e.to_string());
        for (out, relation) in [
            (d.join("dg"), "is"),
            (d.join("link"), "is"),
            (d.join("dg/figures/../."), "is"),
            (d.join("dg/new/deeper"), "lies inside"),
            (d.join("link/new"), "lies inside"),
            (d.join("new/../dg/figures"), "lies inside"),
            (d.join("new/../link/x"), "lies inside"),
            (d.to_path_buf(), "holds"),
        ] {
            let e = refused(&out, &from).unwrap_or_else(|| panic!("{}", out.display()));
            let expected = format!(
                "{} {relation} --from {}",
                out.display(),
                d.join("dg").display()
            );
            assert!(e.starts_with(&expected), "{e}");
        }
        assert_eq!(refused(&d.join("dg2"), &from), None);
        assert_eq!(refused(&d.join("new/dg"), &from), None);
        // A file: only an output that holds it is refused.
        let data = [Input::file("--data", &d.join("a.csv"))];
        assert!(refused(d, &data).unwrap().contains("holds --data"));
        assert_eq!(refused(&d.join("run"), &data), None);
        // An output file: refused when it is an input, by any name.
        std::fs::hard_link(d.join("a.csv"), d.join("b.csv")).unwrap();
        for out in [d.join("a.csv"), d.join("dg/../a.csv"), d.join("b.csv")] {
            let e = check_file(&out, &data).unwrap_err().to_string();
            assert!(e.contains("is --data"), "{e}");
        }
        assert!(check_file(&d.join("c.csv"), &data).is_ok());
        assert!(check_file(&d.join("link/a.csv"), &data).is_ok());
        // The run directory a resumed run goes on in.
        assert_eq!(
            check(&d.join("dg"), &from, &[resolved(&d.join("link"))]).ok(),
            Some(())
        );
    }
}
