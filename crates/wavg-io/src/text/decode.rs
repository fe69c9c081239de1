//! Bytes to text for the line formats: data must be UTF-8, a `#` comment may hold any
//! bytes (a Latin-1 name written by another tool).

use super::LineError;

/// The text of `bytes`, lines of this crate's formats: UTF-8 outside `#` comments; the
/// bytes of a comment that are not UTF-8 become U+FFFD (comments are skipped, so nothing
/// read changes). A line whose data is not UTF-8 is an error naming it, `first_line`
/// being the number of the first line of `bytes`.
///
/// ```
/// use wavg_io::text::decode;
/// assert_eq!(decode(b"v 1 # caf\xe9\n".to_vec(), 1).unwrap(), "v 1 # caf\u{fffd}\n");
/// assert_eq!(decode(b"v 1\nv \xe9\n".to_vec(), 1).unwrap_err().line, 2);
/// ```
pub fn decode(bytes: Vec<u8>, first_line: usize) -> Result<String, LineError> {
    let bytes = match String::from_utf8(bytes) {
        Ok(text) => return Ok(text),
        Err(e) => e.into_bytes(),
    };
    let mut out = String::with_capacity(bytes.len());
    for (i, line) in bytes.split_inclusive(|&b| b == b'\n').enumerate() {
        let hash = line.iter().position(|&b| b == b'#').unwrap_or(line.len());
        let (data, comment) = line.split_at(hash);
        let data = std::str::from_utf8(data).map_err(|_| LineError {
            line: first_line + i,
            message: "the text is not valid UTF-8 (only a # comment may hold other bytes)".into(),
        })?;
        out.push_str(data);
        out.push_str(&String::from_utf8_lossy(comment));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn comments_may_hold_any_bytes_and_data_may_not() {
        let text = decode(
            b"# \xc9l\xe8ve\nv 3 # \xff\xfe\r\nf 1 0.5 0.5 0\n".to_vec(),
            1,
        )
        .unwrap();
        assert_eq!(
            text,
            "# \u{fffd}l\u{fffd}ve\nv 3 # \u{fffd}\u{fffd}\r\nf 1 0.5 0.5 0\n"
        );
        let e = decode(b"v 1\n# ok \xe9\nv \xe92\n".to_vec(), 10).unwrap_err();
        assert_eq!(e.line, 12);
        assert!(e.message.contains("UTF-8"), "{e}");
    }
}
