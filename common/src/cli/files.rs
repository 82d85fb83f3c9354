//! The one check of every command's outputs against its inputs, for all three
//! binaries: which options name a file is read from clap's own definition of
//! the command (a `PathBuf` value, or a path value hint), and which of them
//! are written is `OUTPUTS`, so that a new option is covered the day it is
//! declared. A write that would replace an input (the same name, another
//! spelling of it, a hard or symbolic link) is refused before any work.

use crate::error::bad_input;
use crate::reference::image_io::same_file;
use clap::{Arg, ArgMatches, Command, ValueHint};
use std::path::{Path, PathBuf};

/// The options that name what a command writes, by clap id. Every other option
/// or positional that names a path is an input. An output whose value name is
/// `DIR` is a folder: `--out DIR` of a report command replaces files in it
/// (report.md, results.csv...), so an input file may not lie there either;
/// `--dump-shaders DIR` adds only its own fixed names, so only the folder
/// itself may not be an input.
pub const OUTPUTS: &[&str] = &["out", "heatmap", "unsettled", "dump_shaders"];

/// Options that name a path but are read-only places to look, not files this
/// command reads: `--bin-dir`, where the apps are found.
const NOT_INPUTS: &[&str] = &["bin_dir"];

/// How an output is written.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// One file.
    File,
    /// A folder whose files the command replaces (`compare --out DIR`).
    Folder,
    /// A folder the command adds fixed names to (`--dump-shaders DIR`).
    FolderOfFixedNames,
}

/// Whether `arg` names a path: its value is a `PathBuf`, or it says it is a
/// path by its value hint (`--scene`, a built-in name or a file).
pub fn names_a_path(arg: &Arg) -> bool {
    arg.get_action().takes_values()
        && (arg.get_value_parser().type_id() == std::any::TypeId::of::<PathBuf>()
            || matches!(
                arg.get_value_hint(),
                ValueHint::FilePath | ValueHint::AnyPath | ValueHint::DirPath
            ))
}

/// How `arg` is written, or None when it is read (or names no path).
pub fn output_kind(arg: &Arg) -> Option<Kind> {
    if !names_a_path(arg) || !OUTPUTS.contains(&arg.get_id().as_str()) {
        return None;
    }
    let dir = arg
        .get_value_names()
        .is_some_and(|names| names.iter().any(|n| n.as_str() == "DIR"));
    Some(match (dir, arg.get_id().as_str()) {
        (false, _) => Kind::File,
        (true, "out") => Kind::Folder,
        (true, _) => Kind::FolderOfFixedNames,
    })
}

/// Whether `arg` names a file the command reads.
pub fn is_input(arg: &Arg) -> bool {
    names_a_path(arg) && output_kind(arg).is_none() && !NOT_INPUTS.contains(&arg.get_id().as_str())
}

/// How an option is named in a message: `--out`, or a positional by its value
/// name (`the argument A`).
pub fn label(arg: &Arg) -> String {
    match arg.get_long() {
        Some(long) => format!("--{long}"),
        None => format!(
            "the argument {}",
            arg.get_value_names().and_then(|n| n.first()).map_or_else(
                || arg.get_id().to_string().to_uppercase(),
                |n| n.to_string()
            )
        ),
    }
}

/// One named path of a command line: what names it in a message, and the path.
struct Named {
    what: String,
    path: PathBuf,
}

/// Checks the outputs of the subcommand `matches` ran (or of `cmd` itself:
/// the apps have no subcommands) against its inputs and each other.
pub fn check_command(cmd: &Command, matches: &ArgMatches) -> anyhow::Result<()> {
    let (cmd, matches) = match matches.subcommand() {
        Some((name, sub)) => match cmd.find_subcommand(name) {
            Some(sub_cmd) => (sub_cmd, sub),
            None => return Ok(()),
        },
        None => (cmd, matches),
    };
    let mut outputs = Vec::new();
    let mut inputs = Vec::new();
    for arg in cmd.get_arguments() {
        let id = arg.get_id().as_str();
        // A default (`--out comparison-out`) is a choice too: it must not be an input either.
        let Ok(Some(values)) = matches.try_get_raw(id) else {
            continue;
        };
        for value in values {
            let path = PathBuf::from(value);
            if let Some(kind) = output_kind(arg) {
                outputs.push((label(arg), path, kind));
            } else if is_input(arg) {
                inputs.extend(expand_input(arg, &path));
            }
        }
    }
    check_paths(&outputs, &inputs)
}

/// An input as the files it reads: a scene file is itself and its meshes.
fn expand_input(arg: &Arg, path: &Path) -> Vec<Named> {
    if arg.get_id().as_str() == "scene" {
        return crate::scene::load::scene_inputs(&path.to_string_lossy())
            .into_iter()
            .map(|(what, path)| Named { what, path })
            .collect();
    }
    vec![Named {
        what: label(arg),
        path: path.to_path_buf(),
    }]
}

/// `check_command`'s comparison for one output file against a scene's files,
/// for a caller that holds parsed options rather than clap's matches.
pub fn check_output(option: &str, out: &Path, scene: &str) -> anyhow::Result<()> {
    let inputs: Vec<Named> = crate::scene::load::scene_inputs(scene)
        .into_iter()
        .map(|(what, path)| Named { what, path })
        .collect();
    check_paths(
        &[(option.to_string(), out.to_path_buf(), Kind::File)],
        &inputs,
    )
}

/// The one comparison: each output against each input, and against the outputs before it.
fn check_paths(outputs: &[(String, PathBuf, Kind)], inputs: &[Named]) -> anyhow::Result<()> {
    for (i, (option, out, kind)) in outputs.iter().enumerate() {
        for input in inputs {
            let clash = match kind {
                Kind::File => one_file(out, &input.path),
                Kind::FolderOfFixedNames => same_file(out, &input.path),
                // A file in the folder may bear a name the command writes
                // (report.md, results.csv); a folder in it is left alone.
                Kind::Folder => {
                    same_file(out, &input.path)
                        || input.path.is_file()
                            && input.path.parent().is_some_and(|p| {
                                same_file(
                                    out,
                                    if p.as_os_str().is_empty() {
                                        Path::new(".")
                                    } else {
                                        p
                                    },
                                )
                            })
                }
            };
            if clash {
                let place = if *kind == Kind::File {
                    "file name"
                } else {
                    "folder"
                };
                let whose = if *kind == Kind::Folder && !same_file(out, &input.path) {
                    ", whose files this command replaces, holds"
                } else {
                    " is"
                };
                return Err(bad_input(format!(
                    "{option} '{}'{whose} {} '{}': writing it would replace an input; choose another {place}",
                    out.display(),
                    input.what,
                    input.path.display(),
                )));
            }
        }
        for (other, earlier, _) in &outputs[..i] {
            if one_file(out, earlier) {
                return Err(bad_input(format!(
                    "{option} '{}' is also {other}: one output would replace the other; choose another file name",
                    out.display()
                )));
            }
        }
    }
    Ok(())
}

/// Whether two paths name one file, existing or not: the same file (a link,
/// another spelling), or the same name in the same folder however the folder
/// is spelt (`dir/../x.png` and `x.png`).
pub fn one_file(a: &Path, b: &Path) -> bool {
    let place = |p: &Path| -> Option<PathBuf> {
        let dir = p.parent().filter(|d| !d.as_os_str().is_empty());
        Some(
            std::fs::canonicalize(dir.unwrap_or(Path::new(".")))
                .ok()?
                .join(p.file_name()?),
        )
    };
    same_file(a, b) || place(a).is_some_and(|x| Some(x) == place(b))
}

/// The table-driven test of a binary's command line, kept here so that each
/// binary runs it over its own clap definition: for every command, every
/// (output, input) pair of its options is given one file, spelt four ways
/// (the same path, a hard link, a symbolic link, `sub/../`), and each command
/// line must parse and then be refused by `check_command` with exit code 2,
/// naming the output. Returns each failure in a sentence; `dir` is scratch space.
#[doc(hidden)]
pub fn every_pair_refused(cmd: &Command, dir: &Path) -> Vec<String> {
    let mut failures = Vec::new();
    let mut commands: Vec<(Vec<String>, &Command)> = vec![(vec![], cmd)];
    commands.extend(
        cmd.get_subcommands()
            .map(|c| (vec![c.get_name().to_string()], c)),
    );
    let mut n = 0;
    for (prefix, c) in commands {
        for o in c.get_arguments().filter(|a| output_kind(a).is_some()) {
            for i in c.get_arguments().filter(|a| is_input(a)) {
                n += 1;
                let case = dir.join(format!("pair{n}"));
                let _ = std::fs::remove_dir_all(&case);
                std::fs::create_dir_all(case.join("sub")).expect("scratch folder");
                let input = case.join("input.toml");
                std::fs::write(&input, "input").expect("scratch file");
                let hard = case.join("hard");
                let sym = case.join("sym");
                let linked = std::fs::hard_link(&input, &hard)
                    .and_then(|_| std::os::unix::fs::symlink(&input, &sym));
                linked.expect("links in the scratch folder");
                let mut spellings = vec![input.clone(), hard, sym, case.join("sub/../input.toml")];
                if output_kind(o) == Some(Kind::Folder) {
                    spellings.extend([case.clone(), case.join("sub/..")]);
                }
                for out in spellings {
                    let argv = command_line(&prefix, c, (o, &out), (i, &input), &case);
                    let at = format!("{argv:?}");
                    let result = cmd
                        .clone()
                        .try_get_matches_from(&argv)
                        .map_err(|e| format!("{at} does not parse: {e}"))
                        .and_then(|m| match check_command(cmd, &m) {
                            Ok(()) => Err(format!("{at} is accepted")),
                            Err(e) if crate::error::exit_code_of(&e) != 2 => {
                                Err(format!("{at}: not exit code 2: {e}"))
                            }
                            Err(e) if !e.to_string().contains(&label(o)) => {
                                Err(format!("{at}: the error does not name {}: {e}", label(o)))
                            }
                            Err(_) => Ok(()),
                        });
                    failures.extend(result.err());
                }
            }
        }
    }
    if n == 0 {
        failures.push(format!(
            "{} has no (output, input) pair to test",
            cmd.get_name()
        ));
    }
    failures
}

/// A command line of `cmd` (under `prefix`) with `out` and `input` given their
/// paths, and every other required option or positional a harmless value.
fn command_line(
    prefix: &[String],
    cmd: &Command,
    (o, out): (&Arg, &Path),
    (i, input): (&Arg, &Path),
    dir: &Path,
) -> Vec<String> {
    let mut argv = vec!["program".to_string()];
    argv.extend(prefix.iter().cloned());
    let mut positionals = Vec::new();
    for arg in cmd.get_arguments() {
        let value = if arg.get_id() == o.get_id() {
            out.display().to_string()
        } else if arg.get_id() == i.get_id() {
            input.display().to_string()
        } else if arg.is_required_set() {
            match arg.get_possible_values().first() {
                Some(v) => v.get_name().to_string(),
                None => {
                    let other = dir.join(format!("other-{}", arg.get_id()));
                    std::fs::write(&other, "other").expect("scratch file");
                    other.display().to_string()
                }
            }
        } else {
            continue;
        };
        match arg.get_long() {
            Some(long) => argv.extend([format!("--{long}"), value]),
            None => positionals.push((arg.get_index().unwrap_or(0), value)),
        }
    }
    positionals.sort();
    argv.extend(positionals.into_iter().map(|(_, v)| v));
    argv
}

#[cfg(test)]
mod tests {
    use super::check_output;
    use crate::scene::load::tests::obj_scene;
    use std::path::Path;

    #[test]
    fn an_output_may_not_name_the_scene_or_its_mesh() {
        let dir = std::env::temp_dir().join(format!("twinray-clobber-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("sub")).unwrap();
        let scene = obj_scene(&dir, b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
        let scene = scene.as_str();
        for (out, words) in [
            (
                Path::new(scene).to_path_buf(),
                ["the scene file", "scene.toml"],
            ),
            (
                dir.join("sub/../scene.toml"),
                ["the scene file", "scene.toml"],
            ),
            (dir.join("mesh.obj"), ["the mesh of meshes[0]", "mesh.obj"]),
        ] {
            let e = check_output("--out", &out, scene).unwrap_err();
            for word in words {
                assert!(e.to_string().contains(word), "{e}");
            }
        }
        assert!(check_output("--out", &dir.join("image.png"), scene).is_ok());
        assert!(check_output("--out", &dir.join("scene.toml"), "box").is_ok());
        let _ = std::fs::remove_dir_all(&dir);
    }
}
