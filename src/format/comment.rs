//! Text from outside kiln (a path, a name, a command line) made safe to write inside a comment
//! of generated code: C and C++ (`/* */`, `//` with its backslash-newline splice and `??/`
//! trigraph), Rust and WGSL (whose block comments nest, so `/*` opens one), GLSL, HLSL and
//! JavaScript. Whatever the input, the output is one line of printable ASCII holding none of
//! `*`, `\`, `?`, `` ` ``, `<`, `>` or `%` itself: no comment can be opened or closed, no
//! line continued, no doc markup started. Every other character, and every byte of a non-ASCII
//! one, is written `%XX` (percent-encoding, as in a URL), which a reader decodes by eye.

use std::borrow::Cow;

/// Whether `c` is written as itself.
fn plain(c: char) -> bool {
    c.is_ascii_alphanumeric() || " -_.,:;=+()[]{}@#!~^&|'\"$/".contains(c)
}

/// `text` as it may stand inside any generated comment (see the module's documentation).
#[must_use]
pub fn safe(text: &str) -> Cow<'_, str> {
    if text.chars().all(plain) {
        return Cow::Borrowed(text);
    }
    let mut out = String::with_capacity(text.len() + 8);
    for c in text.chars() {
        if plain(c) {
            out.push(c);
        } else {
            let mut bytes = [0; 4];
            for b in c.encode_utf8(&mut bytes).bytes() {
                out.push_str(&format!("%{b:02X}"));
            }
        }
    }
    Cow::Owned(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each way out of a comment, and what it becomes.
    #[test]
    fn nothing_closes_opens_or_continues_a_comment() {
        for (hostile, written) in [
            ("evil*/int injected_c;/*", "evil%2A/int injected_c;/%2A"),
            ("a\nint x;", "a%0Aint x;"),
            ("a\r\nb", "a%0D%0Ab"),
            ("end\\", "end%5C"),
            ("trigraph??/", "trigraph%3F%3F/"),
            ("50% `code` <b>", "50%25 %60code%60 %3Cb%3E"),
            ("é\u{2028}", "%C3%A9%E2%80%A8"),
            (
                "kiln bake --size 32 --out tables",
                "kiln bake --size 32 --out tables",
            ),
        ] {
            assert_eq!(safe(hostile), written, "{hostile:?}");
        }
    }

    /// The encoding loses nothing: decoding it gives the text back.
    #[test]
    fn percent_decoding_gives_the_text_back() {
        let text = "dir*/x\\y?z%`<>\n\té";
        let encoded = safe(text);
        let mut bytes = Vec::new();
        let mut rest = encoded.as_bytes();
        while let Some((&b, tail)) = rest.split_first() {
            if b == b'%' {
                let hex = std::str::from_utf8(&tail[..2]).unwrap();
                bytes.push(u8::from_str_radix(hex, 16).unwrap());
                rest = &tail[2..];
            } else {
                bytes.push(b);
                rest = tail;
            }
        }
        assert_eq!(String::from_utf8(bytes).unwrap(), text);
    }
}
