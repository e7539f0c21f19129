//! The suite's public case names, as driver CI sees them: `umbrage.` + the short name (what
//! `conform.json`, `--filter` and the `--expect` lists use), with every `-` replaced so that
//! no character of a name is syntax to the runners' filters (gtest's `-` and `:`, the regexes
//! of deqp-runner's skips and flakes, the commas of its CSV files):
//!
//! - `-` before a digit (a minus sign) becomes `m`: `bounds.min_-1_max_2` → `bounds.min_m1_max_2`;
//! - any other `-` becomes `_`: `everitt-kilgard` → `everitt_kilgard`.
//!
//! A public name holds only `a-z`, `0-9`, `_` and `.`. The list of every public name, in run
//! order, is shipped as `conform/umbrage-cases.txt` (`umbrage conform --list` prints it) and
//! is a contract: a renamed case is listed in the CHANGELOG.

/// The package prefix of every public name (`dEQP-VK.` for the Vulkan CTS).
pub const PREFIX: &str = "umbrage.";

/// The shipped case list, relative to the repository root.
pub const SHIPPED_LIST: &str = "conform/umbrage-cases.txt";

/// The public name of short name `short`.
pub fn public(short: &str) -> String {
    let b = short.as_bytes();
    let mut s = String::with_capacity(PREFIX.len() + short.len());
    s.push_str(PREFIX);
    for (i, &c) in b.iter().enumerate() {
        match c {
            b'-' if b.get(i + 1).is_some_and(u8::is_ascii_digit) => s.push('m'),
            b'-' => s.push('_'),
            _ => s.push(c as char),
        }
    }
    s
}

/// Whether `name` uses only the characters a public name may hold.
pub fn is_plain(name: &str) -> bool {
    !name.is_empty() && name.bytes().all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == b'_' || c == b'.')
}

/// dEQP's case pattern: `*` matches any run of characters, everything else itself.
pub fn glob(pattern: &str, name: &str) -> bool {
    fn go(p: &[u8], s: &[u8]) -> bool {
        match (p.first(), s.first()) {
            (None, None) => true,
            (Some(b'*'), _) => go(&p[1..], s) || (!s.is_empty() && go(p, &s[1..])),
            (Some(a), Some(b)) if a == b => go(&p[1..], &s[1..]),
            _ => false,
        }
    }
    go(pattern.as_bytes(), name.as_bytes())
}

/// The share of a list that shard `start` of `fraction` runs (both 1-based, as deqp-runner's
/// `--fraction` and `--fraction-start`): the items at positions `start - 1`,
/// `start - 1 + fraction`, ... The shards `1..=fraction` together hold every item exactly once.
pub fn fraction<T: Clone>(items: &[T], fraction: usize, start: usize) -> Vec<T> {
    items.iter().skip(start.max(1) - 1).step_by(fraction.max(1)).cloned().collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn public_names_are_plain() {
        assert_eq!(public("depth.x.bounds.min_-1_max_2"), "umbrage.depth.x.bounds.min_m1_max_2");
        assert_eq!(public("pipeline.hard_cases.a.everitt-kilgard"), "umbrage.pipeline.hard_cases.a.everitt_kilgard");
        assert!(is_plain("umbrage.a_1.b") && !is_plain("umbrage.a-1") && !is_plain(""));
    }

    #[test]
    fn fractions_partition_the_list() {
        let items: Vec<usize> = (0..103).collect();
        for n in 1..=7 {
            let mut all: Vec<usize> = (1..=n).flat_map(|k| fraction(&items, n, k)).collect();
            all.sort();
            assert_eq!(all, items, "{n} shards");
        }
    }

    #[test]
    fn globs() {
        assert!(glob("umbrage.*", "umbrage.a.b"));
        assert!(glob("umbrage.*.b", "umbrage.a.b"));
        assert!(!glob("umbrage.a", "umbrage.a.b"));
        assert!(glob("umbrage.a.b", "umbrage.a.b"));
    }
}
