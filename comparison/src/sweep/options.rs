//! An option set's `key = value` as the command-line tokens an app reads,
//! and the options a plan may not give (the sweep sets them itself).

/// Options the plan sets for every run itself (or that would break the
/// reading of the report), refused in an option set.
const RESERVED: &[(&str, &str)] = &[
    ("json", "every run reports as JSON"),
    ("headless", "every run is headless"),
    ("frames", "the plan's top-level `frames` sets it"),
    ("settle", "the plan's top-level `settle` sets it"),
    (
        "out",
        "the plan's top-level `images` writes each cell's image",
    ),
    (
        "dump-shaders",
        "the plan's top-level `shaders` dumps each cell's",
    ),
    ("explain", "it prints text where the report is read"),
    ("experiments", "it prints a list instead of rendering"),
    ("help", "it prints help instead of rendering"),
    ("version", "it prints the version instead of rendering"),
];

/// `key = value` of an option set as command-line tokens: `true` is the bare
/// flag, `false` leaves it out, an array repeats the option.
pub fn option_tokens(key: &str, value: &toml::Value) -> Result<Vec<String>, String> {
    if let Some((_, why)) = RESERVED.iter().find(|(k, _)| *k == key) {
        return Err(format!("an option set may not give '{key}': {why}"));
    }
    let flag = format!("--{key}");
    match value {
        toml::Value::Boolean(true) => Ok(vec![flag]),
        toml::Value::Boolean(false) => Ok(Vec::new()),
        toml::Value::String(s) => Ok(vec![flag, s.clone()]),
        toml::Value::Integer(i) => Ok(vec![flag, i.to_string()]),
        toml::Value::Float(x) => Ok(vec![flag, x.to_string()]),
        toml::Value::Array(items) => items.iter().try_fold(Vec::new(), |mut v, item| {
            match item {
                toml::Value::Array(_) | toml::Value::Table(_) => {
                    return Err(format!("'{key}' holds a nested array or table"))
                }
                _ => v.extend(option_tokens(key, item)?),
            }
            Ok(v)
        }),
        _ => Err(format!(
            "'{key}' is a {}; give a string, number or boolean",
            value.type_str()
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::option_tokens;

    #[test]
    fn a_value_becomes_the_tokens_an_app_reads() {
        assert_eq!(
            option_tokens("scene", &toml::Value::String("box".into())).unwrap(),
            ["--scene", "box"]
        );
        assert_eq!(
            option_tokens("count-rays", &toml::Value::Boolean(true)).unwrap(),
            ["--count-rays"]
        );
        assert!(option_tokens("count-rays", &toml::Value::Boolean(false))
            .unwrap()
            .is_empty());
        assert_eq!(
            option_tokens("workgroup", &toml::Value::Integer(8)).unwrap(),
            ["--workgroup", "8"]
        );
        let sets = toml::Value::Array(vec!["a=1".into(), "b=2".into()]);
        assert_eq!(
            option_tokens("set", &sets).unwrap(),
            ["--set", "a=1", "--set", "b=2"]
        );
        assert!(option_tokens("frames", &toml::Value::Integer(3))
            .unwrap_err()
            .contains("top-level"));
    }
}
