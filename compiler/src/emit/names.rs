//! Names of the constants a generated module gives each body and marker
//! (`body::COUPLER`, `marker::COUPLER_P`).
//!
//! The rule, applied in the mechanism's order (bodies in file order;
//! markers body by body, each body's in file order):
//! 1. the name is upper-cased and every character other than an ASCII
//!    letter or digit becomes `_` (a marker's name is `body.marker`, so
//!    `coupler.P` gives `COUPLER_P`);
//! 2. a name that would start with a digit, or be `_` or empty, gets a
//!    leading `_` (`2nd` gives `_2ND`, `-` gives `__`);
//! 3. a name already taken in the same module (`link-1` after `link_1`,
//!    `Coupler` after `coupler`) gets `_2`, `_3`, … — the first free one —
//!    so the first claimant keeps the plain name and every name is stable
//!    as long as the names before it are.
//!
//! Upper-case names are never Rust keywords, so no keyword needs escaping.

use std::collections::HashSet;

/// `name` with every character other than an ASCII letter or digit made
/// `_`, letters in upper or lower case: the start of every identifier the
/// emitter makes from a user's name.
pub(super) fn word(name: &str, upper: bool) -> String {
    name.chars()
        .map(|c| match c {
            c if !c.is_ascii_alphanumeric() => '_',
            c if upper => c.to_ascii_uppercase(),
            c => c.to_ascii_lowercase(),
        })
        .collect()
}

/// The upper-case constant name for `name` (rules 1 and 2).
fn constant(name: &str) -> String {
    let mut s = word(name, true);
    if s.is_empty() || s == "_" || s.starts_with(|c: char| c.is_ascii_digit()) {
        s.insert(0, '_');
    }
    if s == "_" {
        s.push('_');
    }
    s
}

/// Distinct constant names for `names`, in order (rule 3).
pub fn constants<'a>(names: impl IntoIterator<Item = &'a str>) -> Vec<String> {
    let mut taken = HashSet::new();
    names
        .into_iter()
        .map(|name| {
            let base = constant(name);
            let mut c = base.clone();
            let mut n = 2;
            while !taken.insert(c.clone()) {
                c = format!("{base}_{n}");
                n += 1;
            }
            c
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_upper_cased_with_underscores() {
        assert_eq!(
            constants(["coupler", "coupler.P", "Link-1"]),
            ["COUPLER", "COUPLER_P", "LINK_1"]
        );
    }

    #[test]
    fn collisions_are_numbered_in_order() {
        assert_eq!(
            constants(["link_1", "link-1", "LINK.1", "link_1_2", "link1"]),
            ["LINK_1", "LINK_1_2", "LINK_1_3", "LINK_1_2_2", "LINK1"]
        );
    }

    #[test]
    fn digits_keywords_and_underscores_make_valid_identifiers() {
        let names = constants(["2nd", "type", "self.fn", "_", "-", "größe", ""]);
        assert_eq!(names, ["_2ND", "TYPE", "SELF_FN", "__", "___2", "GR__E", "___3"]);
        for n in names {
            assert!(syn::parse_str::<syn::Ident>(&n).is_ok(), "{n}");
        }
    }
}
