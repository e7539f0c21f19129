//! The suite's case list by public name ([`super::names`]): every case in run order, the
//! shipped list it must equal, and the lookup both ways.

use super::names::{glob, public};
use std::collections::HashMap;

/// Every case, in run order: (public name, short name).
pub fn all() -> Vec<(String, String)> {
    super::super::suite::all_names().into_iter().map(|n| (public(&n), n)).collect()
}

/// Every public name, in run order (the shipped list's lines).
pub fn all_public() -> Vec<String> {
    all().into_iter().map(|(p, _)| p).collect()
}

/// Looks names up both ways.
pub struct Index {
    /// (public, short) in run order.
    pub cases: Vec<(String, String)>,
    by_public: HashMap<String, usize>,
    by_short: HashMap<String, usize>,
}

impl Index {
    /// The index of every case.
    pub fn new() -> Index {
        let cases = all();
        let by_public = cases.iter().enumerate().map(|(i, (p, _))| (p.clone(), i)).collect();
        let by_short = cases.iter().enumerate().map(|(i, (_, s))| (s.clone(), i)).collect();
        Index { cases, by_public, by_short }
    }

    /// The position of a case named by its public or its short name.
    pub fn find(&self, name: &str) -> Option<usize> {
        self.by_public.get(name).or_else(|| self.by_short.get(name)).copied()
    }

    /// The positions of the cases that `patterns` select (dEQP's `--deqp-case`: each pattern a
    /// public name with `*` matching any run of characters), in run order.
    pub fn select(&self, patterns: &[String]) -> Vec<usize> {
        (0..self.cases.len()).filter(|&i| patterns.iter().any(|p| glob(p, &self.cases[i].0) || glob(p, &self.cases[i].1))).collect()
    }
}

impl Default for Index {
    fn default() -> Self {
        Self::new()
    }
}

#[cfg(test)]
mod tests {
    use super::super::names::{is_plain, PREFIX, SHIPPED_LIST};
    use super::*;

    #[test]
    fn public_names_are_plain_unique_and_prefixed() {
        let all = all();
        let mut seen = std::collections::HashSet::new();
        for (p, s) in &all {
            assert!(is_plain(p), "{p} (from {s}) holds a character outside a-z 0-9 _ .");
            assert!(p.starts_with(PREFIX));
            assert!(seen.insert(p.clone()), "two cases map to {p}");
        }
    }

    #[test]
    fn the_shipped_list_is_the_codes_list() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").join(SHIPPED_LIST);
        let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let shipped: Vec<&str> = text.lines().collect();
        let code = all_public();
        if shipped != code {
            let missing: Vec<_> = code.iter().filter(|n| !shipped.contains(&n.as_str())).take(5).collect();
            let extra: Vec<_> = shipped.iter().filter(|n| !code.contains(&n.to_string())).take(5).collect();
            panic!(
                "{} differs from the suite ({} shipped, {} in the code; first missing {missing:?}, first extra {extra:?}): \
                 regenerate it with `umbrage conform --list > {SHIPPED_LIST}` and list renamed cases in the CHANGELOG",
                SHIPPED_LIST,
                shipped.len(),
                code.len()
            );
        }
    }
}
