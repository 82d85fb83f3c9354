//! A checked option set and its check: the set's options parsed by each
//! app's own parser (`VulkanCli`, `OpenGlCli`) with the plan's frames and
//! settle, split into the `RenderArgs` both share and an app's own knobs.

use crate::apps::Api;
use clap::{CommandFactory, Parser};
use std::collections::BTreeMap;
use toml::Spanned;
use twinray_common::cli::{OpenGlCli, RenderArgs, VulkanCli};

/// One option set, checked: the `RenderArgs` both apps parsed from it, the
/// options that are an app's own knobs (passed on as written), and its
/// environment.
#[derive(Debug, Clone)]
pub struct OptionSet {
    pub name: String,
    /// The set's options as the plan gave them, in command-line form.
    pub options: Vec<String>,
    pub args: RenderArgs,
    pub extra: Vec<String>,
    pub env: Vec<(String, String)>,
}

/// What every option set is checked with.
pub struct Base<'a> {
    pub apps: &'a [Api],
    pub frames: Option<u32>,
    pub settle: Option<f64>,
}

impl Base<'_> {
    /// Parses `options` as each app would, with the plan's own options, and
    /// splits them into `RenderArgs` and the app's knobs; the error is why an
    /// app refused them.
    pub fn check(
        &self,
        name: String,
        options: Vec<String>,
        env: Vec<(String, String)>,
    ) -> Result<OptionSet, String> {
        let shared: Vec<String> = RenderArgs::command()
            .get_arguments()
            .filter_map(|a| a.get_long().map(|l| format!("--{l}")))
            .collect();
        // Options come in `--key [value]` runs: a run whose key is not one of
        // RenderArgs' own is a knob, passed on after them as written.
        let (mut render, mut extra) = (Vec::new(), Vec::new());
        let mut into_extra = false;
        for token in &options {
            if token.starts_with("--") {
                into_extra = !shared.contains(token);
            }
            if into_extra {
                extra.push(token.clone());
            } else {
                render.push(token.clone());
            }
        }
        let mut argv = vec!["--headless".to_string(), "--json".to_string()];
        if let Some(f) = self.frames {
            argv.extend(["--frames".into(), f.to_string()]);
        }
        if let Some(p) = self.settle {
            argv.extend(["--settle".into(), p.to_string()]);
        }
        argv.extend(render);
        argv.extend(extra.iter().cloned());
        let mut args = None;
        for api in self.apps {
            let bin = api.binary().expect("an app");
            let argv = std::iter::once(bin.to_string()).chain(argv.iter().cloned());
            let parsed = match api {
                Api::Vulkan => VulkanCli::try_parse_from(argv).map(|c| c.render),
                _ => OpenGlCli::try_parse_from(argv).map(|c| c.render),
            };
            let parsed = parsed.map_err(|e| {
                let message = e.to_string();
                let first = message.lines().next().unwrap_or("refused");
                let what = match options.is_empty() {
                    // The plan's own `frames` and `settle`, checked alone.
                    true => "it".to_string(),
                    false => format!("the option set '{name}' ({})", options.join(" ")),
                };
                format!(
                    "{bin} refuses {what}: {}",
                    first.trim_start_matches("error: ")
                )
            })?;
            args.get_or_insert(parsed);
        }
        Ok(OptionSet {
            name,
            options,
            args: args.expect("a plan has an app"),
            extra,
            env,
        })
    }
}

/// The plan's `[env]` with a set's own on top.
pub fn merged_env(
    all: &BTreeMap<String, Spanned<String>>,
    own: &BTreeMap<String, String>,
) -> Vec<(String, String)> {
    let mut env: BTreeMap<String, String> = all
        .iter()
        .map(|(k, v)| (k.clone(), v.get_ref().clone()))
        .collect();
    env.extend(own.iter().map(|(k, v)| (k.clone(), v.clone())));
    env.into_iter().collect()
}
