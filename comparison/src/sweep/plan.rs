//! A sweep's plan file (TOML): what it may say, and every check of it made
//! before the first run, each refusal one sentence naming the plan and the
//! line at fault (exit 2). An option set is checked by the very parsers the
//! apps use (`VulkanCli`, `OpenGlCli`), so an option an app would refuse is
//! refused here, not in the middle of a sweep.

use super::axes::product;
use super::options::option_tokens;
pub use super::sets::OptionSet;
use super::sets::{merged_env, Base};
use crate::apps::Api;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use toml::Spanned;
use twinray_common::error::bad_input;

/// The plan as written. `Spanned` keeps where each value is, for the line
/// a refusal names.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct PlanFile {
    builds: BTreeMap<String, Spanned<String>>,
    apps: Spanned<Vec<String>>,
    #[serde(default)]
    pub(super) axes: BTreeMap<String, Spanned<Vec<toml::Value>>>,
    #[serde(default)]
    pub(super) env_axes: BTreeMap<String, Spanned<Vec<String>>>,
    #[serde(default)]
    sets: Vec<Spanned<SetFile>>,
    #[serde(default)]
    pub(super) env: BTreeMap<String, Spanned<String>>,
    rounds: Spanned<u32>,
    #[serde(default)]
    warmup: u32,
    frames: Option<Spanned<u32>>,
    settle: Option<Spanned<f64>>,
    #[serde(default)]
    ratios: Vec<Spanned<[String; 2]>>,
    /// The device-side steps after the timed rounds (`steps`).
    #[serde(default)]
    shaders: bool,
    images: Option<Spanned<String>>,
}

/// One option set of an explicit `[[sets]]` list.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SetFile {
    name: Option<String>,
    #[serde(default)]
    options: BTreeMap<String, Spanned<toml::Value>>,
    #[serde(default)]
    env: BTreeMap<String, Spanned<String>>,
}

/// A named folder of binaries.
#[derive(Debug, Clone)]
pub struct Build {
    pub name: String,
    pub dir: PathBuf,
}

/// A ratio the table reports: of two apps (per build and set) or of two
/// builds (per app and set), the first over the second.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Ratio {
    Apps(Api, Api),
    Builds(usize, usize),
}

/// One cell: which build, app and option set (indices into the plan).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Cell {
    pub build: usize,
    pub app: Api,
    pub set: usize,
}

/// A finished measured run (warm-up rounds aside), as the table needs it.
pub struct Done {
    pub cell: usize,
    pub report: twinray_common::report::RunReport,
}

/// A checked plan.
#[derive(Debug)]
pub struct Plan {
    pub file: PathBuf,
    pub builds: Vec<Build>,
    pub apps: Vec<Api>,
    pub sets: Vec<OptionSet>,
    pub rounds: u32,
    /// Rounds run before the measured ones and left out of the table.
    pub warmup: u32,
    pub frames: Option<u32>,
    pub settle: Option<f64>,
    pub ratios: Vec<Ratio>,
    /// Each cell once more after the rounds with `--dump-shaders`.
    pub shaders: bool,
    /// Each cell's image, and what it is compared with.
    pub images: Option<Images>,
}

/// What each cell's image is compared with (`images = "..."`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Images {
    /// The first build's, same app and set: byte for byte, with the reports
    /// compared too (timings aside), so that a redesign can be shown to
    /// change no output.
    Builds,
    /// The first app's, same build and set.
    Apps,
    /// The f64 CPU reference of the set's scene, size, `--set` and `--accel`.
    Reference,
    /// The f64 truth of the set's scene, size and `--set`, as the hard
    /// cases are measured against.
    Truth,
}

/// The 1-based line of byte `offset` in `text`.
fn line_of(text: &str, offset: usize) -> usize {
    text[..offset.min(text.len())].matches('\n').count() + 1
}

/// Where a refusal points: the plan's name and text, for "line N" sentences.
pub(super) struct Source<'a> {
    shown: String,
    text: &'a str,
}

impl Source<'_> {
    /// A refusal at the value spanning `span`.
    pub(super) fn at(&self, span: std::ops::Range<usize>, what: String) -> anyhow::Error {
        bad_input(format!(
            "the plan '{}', line {}: {what}",
            self.shown,
            line_of(self.text, span.start)
        ))
    }

    /// A refusal of the plan as a whole (something it lacks has no line).
    fn whole(&self, what: &str) -> anyhow::Error {
        bad_input(format!("the plan '{}': {what}", self.shown))
    }
}

/// Reads and checks the plan at `file`; nothing is run or written.
pub fn load(file: &Path) -> anyhow::Result<Plan> {
    let shown = file.display().to_string();
    let text = std::fs::read_to_string(file)
        .map_err(|e| bad_input(format!("the plan '{shown}' cannot be read ({e})")))?;
    let raw: PlanFile = toml::from_str(&text).map_err(|e| {
        let line = e.span().map_or(1, |s| line_of(&text, s.start));
        bad_input(format!(
            "the plan '{shown}', line {line}: {}",
            e.message().trim().trim_end_matches('.')
        ))
    })?;
    let src = Source { shown, text: &text };
    check_env(&raw, &src)?;
    let apps = apps(&raw, &src)?;
    let builds = builds(&raw, &apps, file.parent().unwrap_or(Path::new(".")), &src)?;
    if *raw.rounds.get_ref() == 0 {
        return Err(src.at(raw.rounds.span(), "`rounds` must be at least 1".into()));
    }
    let frames = raw.frames.as_ref().map(|f| *f.get_ref());
    let settle = raw.settle.as_ref().map(|s| *s.get_ref());
    let base = Base {
        apps: &apps,
        frames,
        settle,
    };
    // The plan's own options alone first, so that a bad `frames` or `settle`
    // is refused at its own line rather than at an option set's.
    if let Some(span) = raw
        .settle
        .as_ref()
        .map(|s| s.span())
        .or_else(|| raw.frames.as_ref().map(|f| f.span()))
    {
        base.check("frames and settle".into(), Vec::new(), Vec::new())
            .map_err(|why| src.at(span, why))?;
    }
    let sets = match (
        raw.axes.is_empty() && raw.env_axes.is_empty(),
        raw.sets.is_empty(),
    ) {
        (true, true) => return Err(src.whole("it names no option set; give [axes] or [[sets]]")),
        (false, false) => {
            let (listed, axes) = (listed(&raw, &base, &src)?, axis_sets(&raw, &base, &src)?);
            super::axes::each_with_each(&listed, &axes, &base)
                .map_err(|why| src.at(raw.sets[0].span(), why))?
        }
        (false, true) => axis_sets(&raw, &base, &src)?,
        (true, false) => listed(&raw, &base, &src)?,
    };
    let ratios = ratios(&raw, &apps, &builds, &src)?;
    let images = match &raw.images {
        None => None,
        Some(v) => Some(match v.get_ref().as_str() {
            "builds" if builds.len() > 1 => Images::Builds,
            "apps" if apps.len() > 1 => Images::Apps,
            "reference" => Images::Reference,
            "truth" => Images::Truth,
            "builds" | "apps" => {
                return Err(src.at(
                    v.span(),
                    format!(
                        "`images = \"{}\"` needs two {} at least",
                        v.get_ref(),
                        v.get_ref()
                    ),
                ))
            }
            other => {
                return Err(src.at(
                    v.span(),
                    format!("`images` is '{other}'; use builds, apps, reference or truth"),
                ))
            }
        }),
    };
    Ok(Plan {
        file: file.to_path_buf(),
        builds,
        apps,
        sets,
        rounds: *raw.rounds.get_ref(),
        warmup: raw.warmup,
        frames,
        settle,
        ratios,
        shaders: raw.shaders,
        images,
    })
}

/// The option sets of the plan's axes (`axes::product`).
fn axis_sets(raw: &PlanFile, base: &Base, src: &Source) -> anyhow::Result<Vec<OptionSet>> {
    product(&raw.axes, &raw.env_axes, &raw.env, base, &|span, why| {
        src.at(span, why)
    })
}

/// Every environment value of the plan, through `env::check`, at its line.
fn check_env(raw: &PlanFile, src: &Source) -> anyhow::Result<()> {
    let sets = raw.sets.iter().flat_map(|s| s.get_ref().env.iter());
    for (var, value) in raw.env.iter().chain(sets) {
        super::env::check(var, value.get_ref()).map_err(|why| src.at(value.span(), why))?;
    }
    for (var, values) in &raw.env_axes {
        for value in values.get_ref() {
            super::env::check(var, value).map_err(|why| src.at(values.span(), why))?;
        }
    }
    Ok(())
}

fn apps(raw: &PlanFile, src: &Source) -> anyhow::Result<Vec<Api>> {
    let apps: Vec<Api> = raw
        .apps
        .get_ref()
        .iter()
        .map(
            |name| match <Api as clap::ValueEnum>::from_str(name, false) {
                Ok(Api::Reference) | Err(_) => Err(src.at(
                    raw.apps.span(),
                    format!("'{name}' is not an app; use vulkan, opengl or opengl-spirv"),
                )),
                Ok(api) => Ok(api),
            },
        )
        .collect::<anyhow::Result<_>>()?;
    if apps.is_empty() {
        return Err(src.at(raw.apps.span(), "`apps` names no app".into()));
    }
    if let Some((_, twice)) = apps
        .iter()
        .enumerate()
        .find(|(i, a)| apps[..*i].contains(a))
    {
        return Err(src.at(
            raw.apps.span(),
            format!("`apps` names {} twice", crate::apps::api_name(*twice)),
        ));
    }
    Ok(apps)
}

/// The builds in the order the plan declares them (the map sorts by name),
/// each a folder, relative to the plan's, that holds every app the plan runs.
fn builds(raw: &PlanFile, apps: &[Api], folder: &Path, src: &Source) -> anyhow::Result<Vec<Build>> {
    let mut declared: Vec<_> = raw.builds.iter().collect();
    declared.sort_by_key(|(_, dir)| dir.span().start);
    if declared.is_empty() {
        return Err(src.whole("[builds] names no build"));
    }
    let mut builds = Vec::new();
    for (name, dir) in declared {
        let path = folder.join(dir.get_ref());
        if !path.is_dir() {
            return Err(src.at(
                dir.span(),
                format!(
                    "build '{name}' is '{}', which is not a folder",
                    path.display()
                ),
            ));
        }
        for api in apps {
            let bin = api.binary().expect("an app");
            if !path.join(bin).is_file() {
                return Err(src.at(
                    dir.span(),
                    format!("build '{name}' ('{}') holds no {bin}", path.display()),
                ));
            }
        }
        builds.push(Build {
            name: name.clone(),
            dir: path,
        });
    }
    Ok(builds)
}

/// The option sets of an explicit `[[sets]]` list.
fn listed(raw: &PlanFile, base: &Base, src: &Source) -> anyhow::Result<Vec<OptionSet>> {
    let mut sets: Vec<OptionSet> = Vec::new();
    for (i, set) in raw.sets.iter().enumerate() {
        let s = set.get_ref();
        let mut opts: Vec<_> = s.options.iter().collect();
        opts.sort_by_key(|(_, v)| v.span().start);
        let mut options = Vec::new();
        for (key, value) in &opts {
            let tokens =
                option_tokens(key, value.get_ref()).map_err(|why| src.at(value.span(), why))?;
            options.extend(tokens);
        }
        let name = s.name.clone().unwrap_or_else(|| format!("set {}", i + 1));
        if sets.iter().any(|o| o.name == name) {
            return Err(src.at(set.span(), format!("two option sets are named '{name}'")));
        }
        let own = s.env.iter().map(|(k, v)| (k.clone(), v.get_ref().clone()));
        let env = merged_env(&raw.env, &own.collect());
        sets.push(
            base.check(name, options, env)
                .map_err(|why| src.at(set.span(), why))?,
        );
    }
    Ok(sets)
}

fn ratios(
    raw: &PlanFile,
    apps: &[Api],
    builds: &[Build],
    src: &Source,
) -> anyhow::Result<Vec<Ratio>> {
    raw.ratios
        .iter()
        .map(|pair| {
            let [a, b] = pair.get_ref();
            let app = |n: &str| apps.iter().copied().find(|api| crate::apps::api_name(*api) == n);
            let build = |n: &str| builds.iter().position(|bd| bd.name == n);
            match (app(a), app(b), build(a), build(b)) {
                (Some(x), Some(y), _, _) => Ok(Ratio::Apps(x, y)),
                (_, _, Some(x), Some(y)) => Ok(Ratio::Builds(x, y)),
                _ => Err(src.at(
                    pair.span(),
                    format!("the ratio ['{a}', '{b}'] names neither two of the plan's apps nor two of its builds"),
                )),
            }
        })
        .collect()
}

impl Plan {
    /// The cells in the order of an even round: builds outermost, then apps, then sets.
    pub fn cells(&self) -> Vec<Cell> {
        let mut cells = Vec::new();
        for build in 0..self.builds.len() {
            for &app in &self.apps {
                for set in 0..self.sets.len() {
                    cells.push(Cell { build, app, set });
                }
            }
        }
        cells
    }
}

#[cfg(test)]
mod tests {
    use super::line_of;

    #[test]
    fn lines_count_from_one() {
        let text = "a = 1\nb = 2\nc = 3\n";
        assert_eq!(line_of(text, 0), 1);
        assert_eq!(line_of(text, 6), 2);
        assert_eq!(line_of(text, text.len() + 10), 4);
    }
}
