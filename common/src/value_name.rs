//! The one spelling of every enum value a user can type or read: the name clap
//! parses (kebab-case unless a variant says otherwise), used alike in argv,
//! reports, CSV columns and shader variant labels.

/// An enum value's name, for every `clap::ValueEnum`.
pub trait ValueName {
    fn name(&self) -> String;
}

impl<T: clap::ValueEnum> ValueName for T {
    fn name(&self) -> String {
        // Only `#[value(skip)]` variants have no possible value, and none is skipped.
        self.to_possible_value()
            .map(|v| v.get_name().to_string())
            .unwrap_or_default()
    }
}
