//! The dEQP test log (`.qpa`), as VK-GL-CTS writes it (`framework/qphelper/qpTestLog.c`) and its
//! `executor/testlog-to-xml` and deqp-runner read it: `#sessionInfo` lines, `#beginSession`,
//! then per case `#beginTestCaseResult NAME`, one XML document
//! (`<TestCaseResult Version="0.3.4" CasePath="NAME" CaseType="SelfValidate">` holding `<Text>`,
//! `<ImageSet>`/`<Image>` (base64 PNG, `CompressionMode="PNG"`), `<Number>` and
//! `<Result StatusCode="…">`), `#endTestCaseResult`; and `#endSession`.

use super::exec::Code;
use std::fmt::Write as _;

/// The session's header: the lines before the first case.
pub fn session_header(command_line: &str) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "#sessionInfo releaseName umbrage-{}", env!("CARGO_PKG_VERSION"));
    let _ = writeln!(s, "#sessionInfo releaseId 0x00000000");
    let _ = writeln!(s, "#sessionInfo targetName \"umbrage conform\"");
    let _ = writeln!(s, "#sessionInfo commandLineParameters \"{}\"", command_line.replace('"', "'"));
    s.push_str("\n#beginSession\n");
    s
}

/// The session's last line.
pub const SESSION_END: &str = "\n#endSession\n";

/// One image of a case's record.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    /// `Name` (e.g. `expected`).
    pub name: String,
    /// `Description` (e.g. the file it was read from).
    pub description: String,
    /// Pixels across.
    pub width: u32,
    /// Pixels down.
    pub height: u32,
    /// The PNG file's bytes.
    pub png: Vec<u8>,
}

impl Image {
    /// Reads a PNG written for a failure (`name` is the file stem).
    pub fn from_png_file(path: &std::path::Path) -> std::result::Result<Image, String> {
        let png = std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
        let (width, height) = image::image_dimensions(path).map_err(|e| format!("{}: {e}", path.display()))?;
        let name = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
        Ok(Image { name, description: path.file_name().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default(), width, height, png })
    }
}

/// One case's record, from `#beginTestCaseResult` to `#endTestCaseResult` (both included).
pub fn case_record(name: &str, code: Code, texts: &[String], images: &[Image], micros: u64) -> String {
    let msg = texts.last().map(String::as_str).unwrap_or("");
    let mut s = String::new();
    let _ = writeln!(s, "\n#beginTestCaseResult {name}");
    s.push_str("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    let _ = writeln!(s, "<TestCaseResult Version=\"0.3.4\" CasePath=\"{}\" CaseType=\"SelfValidate\">", esc(name));
    for t in texts {
        let _ = writeln!(s, " <Text>{}</Text>", esc(t));
    }
    if !images.is_empty() {
        s.push_str(" <ImageSet Name=\"Failure\" Description=\"Expected, actual and difference\">\n");
        for im in images {
            let _ = writeln!(
                s,
                "  <Image Name=\"{}\" Width=\"{}\" Height=\"{}\" Format=\"RGB888\" CompressionMode=\"PNG\" Description=\"{}\">{}</Image>",
                esc(&im.name),
                im.width,
                im.height,
                esc(&im.description),
                base64(&im.png)
            );
        }
        s.push_str(" </ImageSet>\n");
    }
    let _ = writeln!(
        s,
        " <Number Name=\"TestDuration\" Description=\"Test case duration in microseconds\" Tag=\"Time\" Unit=\"us\">{micros}</Number>"
    );
    let _ = writeln!(s, " <Result StatusCode=\"{}\">{}</Result>", code.name(), esc(msg));
    s.push_str("</TestCaseResult>\n\n#endTestCaseResult\n");
    s
}

/// XML text and attribute escaping ([`crate::junit::escape`]), with tabs and newlines as
/// spaces and other control characters as `?` (a QPA record's text stays on its line).
pub fn esc(s: &str) -> String {
    let flat: String = s
        .chars()
        .map(|c| match c {
            '\n' | '\t' => ' ',
            c if (c as u32) < 0x20 => '?',
            c => c,
        })
        .collect();
    crate::junit::escape(&flat)
}

const B64: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

/// Standard base64 with padding (what dEQP's `<Image>` holds).
pub fn base64(data: &[u8]) -> String {
    let mut o = String::with_capacity(data.len().div_ceil(3) * 4);
    for c in data.chunks(3) {
        let n = (c[0] as u32) << 16 | (*c.get(1).unwrap_or(&0) as u32) << 8 | *c.get(2).unwrap_or(&0) as u32;
        for k in 0..4 {
            if k <= c.len() {
                o.push(B64[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                o.push('=');
            }
        }
    }
    o
}

/// Decodes [`base64`] (whitespace ignored); `None` on a character outside the alphabet.
pub fn unbase64(text: &str) -> Option<Vec<u8>> {
    let mut out = Vec::with_capacity(text.len() / 4 * 3);
    let (mut acc, mut bits) = (0u32, 0u32);
    for c in text.bytes().filter(|c| !c.is_ascii_whitespace()) {
        if c == b'=' {
            break;
        }
        let v = B64.iter().position(|&b| b == c)? as u32;
        acc = acc << 6 | v;
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out.push((acc >> bits) as u8);
            acc &= (1 << bits) - 1;
        }
    }
    Some(out)
}

/// One case read back from a log: what [`parse`] finds.
#[derive(Clone, Debug, PartialEq)]
pub struct Record {
    /// The name after `#beginTestCaseResult`.
    pub name: String,
    /// The XML document between the markers.
    pub xml: String,
}

/// Splits a log into its case records, as deqp-runner and testlog-to-xml delimit them: the
/// name after `#beginTestCaseResult`, the XML up to `#endTestCaseResult`. Errors name the
/// line of a record left open or a marker outside a session.
pub fn parse(log: &str) -> std::result::Result<Vec<Record>, String> {
    let mut out = Vec::new();
    let mut in_session = false;
    let mut open: Option<(String, String, usize)> = None;
    for (i, line) in log.lines().enumerate() {
        if let Some((_, xml, _)) = &mut open {
            if line == "#endTestCaseResult" {
                let (name, xml, _) = open.take().unwrap_or_default();
                out.push(Record { name, xml });
            } else if line.starts_with('#') {
                return Err(format!("line {}: '{line}' inside a case record", i + 1));
            } else {
                xml.push_str(line);
                xml.push('\n');
            }
            continue;
        }
        match line {
            "#beginSession" => in_session = true,
            "#endSession" => in_session = false,
            _ if line.starts_with("#beginTestCaseResult ") => {
                if !in_session {
                    return Err(format!("line {}: a case outside #beginSession", i + 1));
                }
                open = Some((line["#beginTestCaseResult ".len()..].to_string(), String::new(), i + 1));
            }
            _ => {}
        }
    }
    match open {
        Some((name, _, line)) => Err(format!("line {line}: the record of {name} has no #endTestCaseResult")),
        None => Ok(out),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_round_trips() {
        for n in 0..40u8 {
            let data: Vec<u8> = (0..n).map(|i| i.wrapping_mul(37)).collect();
            assert_eq!(unbase64(&base64(&data)).unwrap(), data);
        }
        assert_eq!(base64(b"Man"), "TWFu");
        assert_eq!(base64(b"Ma"), "TWE=");
        assert_eq!(base64(b"M"), "TQ==");
    }

    /// The writer against the format, read with a real XML parser the way testlog-to-xml and
    /// deqp-runner do: markers, one well-formed document per case, CasePath = the name, the
    /// status code, and each image's base64 a PNG of the stated size.
    #[test]
    fn records_parse_as_deqp_logs() {
        let img = image::RgbImage::from_fn(8, 4, |x, y| image::Rgb([x as u8 * 30, y as u8 * 60, 7]));
        let mut png = Vec::new();
        img.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png).unwrap();
        let im = Image { name: "actual".into(), description: "actual.png".into(), width: 8, height: 4, png };
        let mut log = session_header("--deqp-case=umbrage.*");
        log += &case_record("umbrage.a.b", Code::Fail, &["what <it> checks".into(), "3 stencil & 0 depth".into()], &[im], 1234);
        log += &case_record("umbrage.a.c", Code::NotSupported, &["no depthBounds".into()], &[], 0);
        log += &case_record("umbrage.a.d", Code::Timeout, &[], &[], 5);
        log += SESSION_END;
        let recs = parse(&log).unwrap();
        assert_eq!(recs.iter().map(|r| r.name.as_str()).collect::<Vec<_>>(), ["umbrage.a.b", "umbrage.a.c", "umbrage.a.d"]);
        let want = [("Fail", 1), ("NotSupported", 0), ("Timeout", 0)];
        for (r, (code, images)) in recs.iter().zip(want) {
            let mut reader = quick_xml::Reader::from_str(&r.xml);
            let (mut path, mut status, mut seen_images, mut in_image, mut top) = (None, None, 0, None::<(u32, u32)>, 0);
            loop {
                match reader.read_event().unwrap_or_else(|e| panic!("{}: {e}\n{}", r.name, r.xml)) {
                    quick_xml::events::Event::Start(e) | quick_xml::events::Event::Empty(e) => {
                        let attr = |k: &str| {
                            e.attributes()
                                .flatten()
                                .find(|a| a.key.as_ref() == k.as_bytes())
                                .map(|a| String::from_utf8_lossy(&a.value).into_owned())
                        };
                        match e.name().as_ref() {
                            b"TestCaseResult" => {
                                top += 1;
                                path = attr("CasePath");
                                assert_eq!(attr("CaseType").as_deref(), Some("SelfValidate"));
                            }
                            b"Result" => status = attr("StatusCode"),
                            b"Image" => {
                                assert_eq!(attr("CompressionMode").as_deref(), Some("PNG"));
                                let w: u32 = attr("Width").unwrap().parse().unwrap();
                                let h: u32 = attr("Height").unwrap().parse().unwrap();
                                in_image = Some((w, h));
                            }
                            _ => {}
                        }
                    }
                    quick_xml::events::Event::Text(t) => {
                        if let Some((w, h)) = in_image.take() {
                            let bytes = unbase64(std::str::from_utf8(t.as_ref()).unwrap()).unwrap();
                            let decoded = image::load_from_memory(&bytes).unwrap();
                            assert_eq!((decoded.width(), decoded.height()), (w, h));
                            seen_images += 1;
                        }
                    }
                    quick_xml::events::Event::Eof => break,
                    _ => {}
                }
            }
            assert_eq!(top, 1, "one TestCaseResult per record");
            assert_eq!(path.as_deref(), Some(r.name.as_str()));
            assert_eq!(status.as_deref(), Some(code));
            assert_eq!(seen_images, images);
        }
        // A record left open is an error, not a silently shorter log.
        assert!(parse("#beginSession\n#beginTestCaseResult x\n<a/>\n").is_err());
    }
}
