//! What each key of the README's Controls section asks the window to do.

use winit::keyboard::{Key, NamedKey};

/// What a key or gesture asks for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Action {
    Quit,
    Scene(&'static str),
    ResetCamera,
    Screenshot,
    DepthUp,
    DepthDown,
    /// Fragment ↔ compute.
    SwitchPath,
}

/// The keys of the README's Controls section. `=` counts as `+` (same key
/// without shift on US layouts), `_` as `-`.
pub fn action_for_key(key: &Key) -> Option<Action> {
    match key {
        Key::Named(NamedKey::Escape) => Some(Action::Quit),
        Key::Character(c) => action_for_char(c.as_str()),
        _ => None,
    }
}

pub(crate) fn action_for_char(c: &str) -> Option<Action> {
    Some(match c {
        "1" => Action::Scene("teapot"),
        "2" => Action::Scene("box"),
        "3" => Action::Scene("spherelist"),
        "r" | "R" => Action::ResetCamera,
        "p" | "P" => Action::Screenshot,
        "+" | "=" => Action::DepthUp,
        "-" | "_" => Action::DepthDown,
        "c" | "C" => Action::SwitchPath,
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_map_to_the_documented_actions() {
        let ch = |s: &str| action_for_key(&Key::Character(s.into()));
        assert_eq!(
            action_for_key(&Key::Named(NamedKey::Escape)),
            Some(Action::Quit)
        );
        assert_eq!(ch("1"), Some(Action::Scene("teapot")));
        assert_eq!(ch("2"), Some(Action::Scene("box")));
        assert_eq!(ch("3"), Some(Action::Scene("spherelist")));
        assert_eq!(ch("R"), Some(Action::ResetCamera));
        assert_eq!(ch("p"), Some(Action::Screenshot));
        assert_eq!(ch("+"), Some(Action::DepthUp));
        assert_eq!(ch("="), Some(Action::DepthUp));
        assert_eq!(ch("-"), Some(Action::DepthDown));
        assert_eq!(ch("c"), Some(Action::SwitchPath));
        assert_eq!(ch("C"), Some(Action::SwitchPath));
        assert_eq!(ch("x"), None);
        assert_eq!(action_for_key(&Key::Named(NamedKey::Enter)), None);
    }
}
