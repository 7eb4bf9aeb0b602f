//! CSV cells (RFC 4180), shared by every CSV this crate writes (results, slopes, benchmarks).

/// A CSV cell holding `t`, quoted when it has a comma, a quote or a line break.
pub fn field(t: &str) -> String {
    if t.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", t.replace('"', "\"\""))
    } else {
        t.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_are_quoted_when_they_need_it() {
        assert_eq!(field("bvh"), "bvh");
        assert_eq!(field("a,b.obj"), "\"a,b.obj\"");
        assert_eq!(field("say \"x\""), "\"say \"\"x\"\"\"");
        assert_eq!(field("two\nlines"), "\"two\nlines\"");
    }
}
