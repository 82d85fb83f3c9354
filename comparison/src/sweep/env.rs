//! A plan's environment variables, checked when the plan is read. A
//! variable that an app reads as one of its knobs (`env = ...` in
//! common::cli) is parsed by that knob's own value parser, so a misspelt
//! value is refused before the first run instead of failing every run of the
//! sweep. A `TWINRAY_` name that no app reads is refused too: a misspelt name
//! would otherwise run every cell at the default and look like a measurement
//! of the variable. Any other name (a driver's, `__GL_SHADER_DISK_CACHE`,
//! `MESA_...`) is the driver's business and is passed on as written.

use clap::CommandFactory;
use std::ffi::OsStr;
use twinray_common::cli::{OpenGlCli, VulkanCli};

/// The apps' command lines, each with its binary's name.
fn commands() -> [(&'static str, clap::Command); 2] {
    [
        ("twinray-vk", VulkanCli::command()),
        ("twinray-gl", OpenGlCli::command()),
    ]
}

/// Every variable the apps read, for the refusal of one they do not.
fn known() -> Vec<String> {
    let mut names: Vec<String> = commands()
        .iter()
        .flat_map(|(_, cmd)| {
            cmd.get_arguments()
                .filter_map(|a| a.get_env().map(|e| e.to_string_lossy().into_owned()))
                .collect::<Vec<_>>()
        })
        .collect();
    names.sort();
    names.dedup();
    names
}

/// Why `var = value` cannot be set for a run, or nothing.
pub fn check(var: &str, value: &str) -> Result<(), String> {
    if var.is_empty() || var.contains(['=', '\0']) {
        return Err(format!("'{var}' is not an environment variable's name"));
    }
    if value.contains('\0') {
        return Err(format!("the value of {var} holds a NUL byte"));
    }
    let mut read = false;
    for (bin, cmd) in commands() {
        let Some(arg) = cmd
            .get_arguments()
            .find(|a| a.get_env() == Some(OsStr::new(var)))
        else {
            continue;
        };
        read = true;
        let option = arg
            .get_long()
            .map_or_else(|| arg.get_id().to_string(), |l| format!("--{l}"));
        // The knob alone, taking its value as an option's: its own value
        // parser then reads the variable's text, flags' booleans included.
        let alone = clap::Command::new(bin).arg(arg.clone().action(clap::ArgAction::Set));
        alone
            .try_get_matches_from([bin, option.as_str(), value])
            .map_err(|e| {
                let message = e.to_string();
                let first = message.lines().next().unwrap_or("refused");
                let possible = message
                    .split("[possible values: ")
                    .nth(1)
                    .and_then(|rest| rest.split(']').next())
                    .map_or(String::new(), |list| format!(" (it takes {list})"));
                format!(
                    "{bin} refuses {var} = '{value}', its {option}: {}{possible}",
                    first.trim_start_matches("error: ")
                )
            })?;
    }
    if !read && var.starts_with("TWINRAY_") {
        return Err(format!(
            "no app reads {var} (the apps read {})",
            known().join(", ")
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::check;

    #[test]
    fn a_knobs_value_is_parsed_as_its_app_parses_it() {
        assert!(check("TWINRAY_VK_WAIT", "idle").is_ok());
        let why = check("TWINRAY_VK_WAIT", "idel").unwrap_err();
        assert!(
            why.contains("twinray-vk refuses TWINRAY_VK_WAIT = 'idel'"),
            "{why}"
        );
        assert!(why.contains("fence, idle"), "{why}");
        assert!(check("TWINRAY_VK_SYNC2", "1").is_ok());
        assert!(check("TWINRAY_VK_SYNC2", "perhaps").is_err());
        assert!(check("TWINRAY_GL_DEVICE", "x").is_err());
    }

    #[test]
    fn an_unknown_twinray_name_is_refused_and_a_drivers_passes() {
        let why = check("TWINRAY_VK_WIAT", "idle").unwrap_err();
        assert!(why.contains("TWINRAY_VK_WAIT"), "{why}");
        assert!(check("__GL_SHADER_DISK_CACHE", "0").is_ok());
        assert!(check("A=B", "1").is_err());
    }
}
