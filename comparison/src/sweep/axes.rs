//! A plan's `[axes]` and `[env_axes]`: every combination of their values is
//! one option set, the first declared axis outermost; with a `[[sets]]` list
//! as well, each listed set is combined with each combination (the points of
//! a study, say, each on both paths).

use super::options::option_tokens;
use super::sets::{merged_env, Base, OptionSet};
use toml::Spanned;

/// A refusal at the plan's line holding a span.
type At<'a> = &'a dyn Fn(std::ops::Range<usize>, String) -> anyhow::Error;
use std::collections::BTreeMap;

/// Each listed set with each combination of the axes: the listed set's
/// options first, its name first, its environment on top.
pub fn each_with_each(
    listed: &[OptionSet],
    axes: &[OptionSet],
    base: &Base,
) -> Result<Vec<OptionSet>, String> {
    let mut sets = Vec::new();
    for l in listed {
        for a in axes {
            let mut env: BTreeMap<String, String> = a.env.iter().cloned().collect();
            env.extend(l.env.iter().cloned());
            let options = l.options.iter().chain(&a.options).cloned().collect();
            let name = format!("{} {}", l.name, a.name);
            sets.push(base.check(name, options, env.into_iter().collect())?);
        }
    }
    Ok(sets)
}

/// One value of one axis: its command-line tokens or environment variable,
/// and its part of the set's name.
enum Pick {
    Option(Vec<String>),
    Env(String, String),
}

/// An axis: where the plan declares it, and its values with their names.
type Axis = (std::ops::Range<usize>, Vec<(String, Pick)>);

/// Why an axis's values cannot be its cells: none, or one twice (two cells
/// the table could not tell apart).
fn distinct<T: PartialEq>(key: &str, all: &[T], show: impl Fn(&T) -> String) -> Result<(), String> {
    if all.is_empty() {
        return Err(format!("the axis '{key}' is empty"));
    }
    match all.iter().enumerate().find(|(i, v)| all[..*i].contains(v)) {
        Some((_, v)) => Err(format!("the axis '{key}' names {} twice", show(v))),
        None => Ok(()),
    }
}

/// The option sets of `[axes]` and `[env_axes]`: every combination, the
/// first declared axis outermost.
pub fn product(
    option_axes: &BTreeMap<String, Spanned<Vec<toml::Value>>>,
    env_axes: &BTreeMap<String, Spanned<Vec<String>>>,
    env: &BTreeMap<String, Spanned<String>>,
    base: &Base,
    at: At,
) -> anyhow::Result<Vec<OptionSet>> {
    // Each axis as (where it is, its values), in the order the plan declares them.
    let mut axes: Vec<Axis> = Vec::new();
    for (key, values) in option_axes {
        distinct(key, values.get_ref(), |v| v.to_string()).map_err(|why| at(values.span(), why))?;
        let picks = values
            .get_ref()
            .iter()
            .map(|v| {
                let tokens = option_tokens(key, v).map_err(|why| at(values.span(), why))?;
                let shown = match v {
                    toml::Value::String(s) => s.clone(),
                    other => other.to_string(),
                };
                Ok((format!("{key}={shown}"), Pick::Option(tokens)))
            })
            .collect::<anyhow::Result<_>>()?;
        axes.push((values.span(), picks));
    }
    for (var, values) in env_axes {
        distinct(var, values.get_ref(), |v| format!("'{v}'"))
            .map_err(|why| at(values.span(), why))?;
        let picks = values
            .get_ref()
            .iter()
            .map(|v| (format!("{var}={v}"), Pick::Env(var.clone(), v.clone())))
            .collect();
        axes.push((values.span(), picks));
    }
    axes.sort_by_key(|(span, _)| span.start);
    // Each option alone first, so that a refusal names the axis that holds it.
    for (span, picks) in &axes {
        for (name, pick) in picks {
            if let Pick::Option(tokens) = pick {
                base.check(name.clone(), tokens.clone(), Vec::new())
                    .map_err(|why| at(span.clone(), why))?;
            }
        }
    }
    let mut combos: Vec<Vec<usize>> = vec![Vec::new()];
    for (_, picks) in &axes {
        combos = combos
            .into_iter()
            .flat_map(|c| {
                (0..picks.len()).map(move |i| {
                    let mut c = c.clone();
                    c.push(i);
                    c
                })
            })
            .collect();
    }
    combos
        .into_iter()
        .map(|combo| {
            let mut names = Vec::new();
            let mut options = Vec::new();
            let mut own_env = BTreeMap::new();
            for ((_, picks), &i) in axes.iter().zip(&combo) {
                let (name, pick) = &picks[i];
                names.push(name.clone());
                match pick {
                    Pick::Option(tokens) => options.extend(tokens.iter().cloned()),
                    Pick::Env(k, v) => {
                        own_env.insert(k.clone(), v.clone());
                    }
                }
            }
            let name = names.join(" ");
            let env = merged_env(env, &own_env);
            // The refusal names the first axis: the set is their combination.
            base.check(name, options, env)
                .map_err(|why| at(axes[0].0.clone(), why))
        })
        .collect()
}
