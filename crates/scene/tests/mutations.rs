//! Robustness: thousands of corrupted versions of the shipped scenes (lines deleted, files
//! truncated, numbers replaced by NaN, infinities, negatives, huge values or strings, brackets
//! dropped) must each load or fail with a one-line error — never panic.

use std::path::Path;

/// xorshift64*: a fixed stream, so every run tries the same mutations.
struct Rng(u64);
impl Rng {
    fn below(&mut self, n: usize) -> usize {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 33) as usize % n.max(1)
    }
}

const REPLACEMENTS: [&str; 10] = [
    "nan",
    "-1.0",
    "0",
    "1e40",
    "-inf",
    "\"x\"",
    "[]",
    "[1, 2]",
    "true",
    "4294967296",
];

fn mutate(text: &str, rng: &mut Rng) -> String {
    let lines: Vec<&str> = text.lines().collect();
    match rng.below(4) {
        0 => {
            let drop = rng.below(lines.len());
            lines
                .iter()
                .enumerate()
                .filter(|(i, _)| *i != drop)
                .map(|(_, l)| *l)
                .collect::<Vec<_>>()
                .join("\n")
        }
        1 => {
            let mut cut = rng.below(text.len());
            while !text.is_char_boundary(cut) {
                cut -= 1;
            }
            text[..cut].to_string()
        }
        2 => {
            // Replace one number (a run of digits, '.', '-', 'e') with a hostile value.
            let starts: Vec<usize> = text
                .char_indices()
                .filter(|&(i, c)| {
                    c.is_ascii_digit()
                        && (i == 0 || !text.as_bytes()[i - 1].is_ascii_alphanumeric())
                })
                .map(|(i, _)| i)
                .collect();
            if starts.is_empty() {
                return text.to_string();
            }
            let s = starts[rng.below(starts.len())];
            let e = s + text[s..]
                .find(|c: char| !(c.is_ascii_digit() || c == '.' || c == 'e' || c == '-'))
                .unwrap_or(text.len() - s);
            format!(
                "{}{}{}",
                &text[..s],
                REPLACEMENTS[rng.below(REPLACEMENTS.len())],
                &text[e..]
            )
        }
        _ => {
            let brackets: Vec<usize> = text
                .char_indices()
                .filter(|&(_, c)| c == '[' || c == ']')
                .map(|(i, _)| i)
                .collect();
            if brackets.is_empty() {
                return text.to_string();
            }
            let b = brackets[rng.below(brackets.len())];
            format!("{}{}", &text[..b], &text[b + 1..])
        }
    }
}

#[test]
fn corrupted_scenes_never_panic() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let mut errors = 0;
    let mut tried = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|e| e != "toml") {
            continue;
        }
        let text = std::fs::read_to_string(&path).unwrap();
        for _ in 0..300 {
            let bad = mutate(&text, &mut rng);
            let result = std::panic::catch_unwind(|| {
                rt_scene::load_str(&bad, &dir, Path::new("mutant.toml"))
            });
            let Ok(result) = result else {
                panic!(
                    "load_str panicked on a mutation of {}:\n{bad}",
                    path.display()
                );
            };
            tried += 1;
            if let Err(e) = result {
                errors += 1;
                let msg = e.to_string();
                assert!(!msg.contains('\n'), "multi-line error: {msg}");
                assert!(
                    msg.contains("mutant.toml")
                        || msg.contains(&*dir.to_string_lossy())
                        || msg.contains("scenes"),
                    "error names no file: {msg}"
                );
            }
        }
    }
    // The mutations must actually exercise the error paths.
    assert!(
        errors > tried / 3,
        "only {errors} of {tried} mutants were rejected"
    );
}
