//! JUnit XML: one `<testsuite>` per group and configuration, one `<testcase>` per case,
//! `<failure>` with what differed, `<skipped>` with the missing feature. The layout is the
//! one CI systems (Jenkins, GitLab, GitHub test reporters) read: `testsuites` > `testsuite`
//! (tests / failures / errors / skipped / time) > `testcase` (name, classname, time).

use super::suite::Report;
use super::Status;
use std::fmt::Write as _;

/// `s` escaped for an XML attribute or text node (control characters other than tab,
/// newline and carriage return, which XML 1.0 forbids, are dropped).
pub fn escape(s: &str) -> String {
    let mut o = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => o.push_str("&amp;"),
            '<' => o.push_str("&lt;"),
            '>' => o.push_str("&gt;"),
            '"' => o.push_str("&quot;"),
            '\'' => o.push_str("&apos;"),
            '\t' | '\n' | '\r' => o.push(c),
            c if (c as u32) < 0x20 => {}
            c => o.push(c),
        }
    }
    o
}

/// The suite (testsuite) a case belongs to: its group and configuration.
fn suite_of(c: &super::suite::CaseOutcome) -> String {
    match &c.config {
        Some(cfg) => format!("{}.{cfg}", c.group),
        None => c.group.clone(),
    }
}

/// The report as JUnit XML.
pub fn junit(report: &Report) -> String {
    let mut suites: Vec<(String, Vec<&super::suite::CaseOutcome>)> = Vec::new();
    for c in &report.cases {
        let s = suite_of(c);
        match suites.iter_mut().find(|(n, _)| *n == s) {
            Some((_, v)) => v.push(c),
            None => suites.push((s, vec![c])),
        }
    }
    let (_, failed, skipped) = report.counts();
    let errors = report.crashed().len();
    let mut x = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    let _ = writeln!(
        x,
        "<testsuites name=\"umbrage conform\" tests=\"{}\" failures=\"{failed}\" errors=\"{errors}\" skipped=\"{skipped}\" time=\"{:.3}\">",
        report.cases.len(),
        report.seconds
    );
    let d = &report.device;
    for (name, cases) in &suites {
        let f = cases.iter().filter(|c| c.status == Status::Fail).count();
        let s = cases.iter().filter(|c| c.status == Status::Skipped).count();
        let e = cases.iter().filter(|c| matches!(c.status, Status::Crash | Status::Timeout)).count();
        let t: f64 = cases.iter().map(|c| c.seconds).sum();
        let _ = writeln!(
            x,
            "  <testsuite name=\"{}\" tests=\"{}\" failures=\"{f}\" errors=\"{e}\" skipped=\"{s}\" time=\"{t:.3}\">",
            escape(name),
            cases.len()
        );
        x.push_str("    <properties>\n");
        for (k, v) in [
            ("device", d.name.as_str()),
            ("driver", d.driver.as_str()),
            ("driver_info", d.driver_info.as_str()),
            ("vulkan_api", d.api_version.as_str()),
            ("validation", if report.validation { "on" } else { "off" }),
        ] {
            let _ = writeln!(x, "      <property name=\"{k}\" value=\"{}\"/>", escape(v));
        }
        x.push_str("    </properties>\n");
        for c in cases {
            let _ = write!(
                x,
                "    <testcase name=\"{}\" classname=\"umbrage.conform.{}\" time=\"{:.6}\"",
                escape(&c.name),
                escape(name),
                c.seconds
            );
            match c.status {
                Status::Pass => x.push_str("/>\n"),
                Status::Skipped => {
                    let _ = writeln!(x, ">\n      <skipped message=\"{}\"/>\n    </testcase>", escape(&c.message));
                }
                Status::Crash | Status::Timeout => {
                    let _ = writeln!(
                        x,
                        ">\n      <error message=\"{}\" type=\"{}\">{}</error>\n    </testcase>",
                        escape(&c.message),
                        c.status.name(),
                        escape(&c.message)
                    );
                }
                Status::Fail => {
                    let mut body = c.message.clone();
                    if !c.images.is_empty() {
                        body.push_str("\nimages: ");
                        body.push_str(&c.images.join(", "));
                    }
                    if let Some(b) = &c.bug {
                        body.push_str(&format!("\nknown bug: {} ({})", b.title, b.url));
                    }
                    let first = c.message.split("; ").next().unwrap_or("");
                    let _ = writeln!(
                        x,
                        ">\n      <failure message=\"{}\" type=\"mismatch\">{}</failure>\n    </testcase>",
                        escape(first),
                        escape(&body)
                    );
                }
            }
        }
        x.push_str("  </testsuite>\n");
    }
    x.push_str("</testsuites>\n");
    x
}

#[cfg(test)]
mod tests {
    #[test]
    fn escapes_markup_and_drops_control_characters() {
        assert_eq!(super::escape("a<b & \"c\" 'd'>\u{1}"), "a&lt;b &amp; &quot;c&quot; &apos;d&apos;&gt;");
    }
}
