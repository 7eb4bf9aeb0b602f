//! Robustness: thousands of corrupted versions of the shipped scenes (lines deleted, files
//! truncated, numbers replaced by NaN, infinities, negatives, huge values or strings, brackets
//! dropped) must each load or fail with a one-line error — never panic. A mutant that loads is
//! a scene like any other, the case of a silently wrong image: it must render (8 × 8 pixels,
//! 2 samples, the default acceleration structure) without a panic, without a discarded sample
//! and without an invalid value in the film. The scenes are taken in name order and the
//! mutations from a fixed stream (`rt_testkit::Rng`), so every run tries the same mutants.

use rt_testkit::{stats::invalid_values, Renderer, Rng, SceneExt};
use std::path::Path;

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

/// Renders a mutant that loaded: no panic, no discarded sample, no invalid value.
fn render_mutant(scene: rt_core::Scene, text: &str, original: &Path) {
    let scene = scene.with_resolution(8, 8);
    let result = std::panic::catch_unwind(|| {
        let integrator = rt_integrators::PathIntegrator::new(4);
        let buffers = rt_film::FilmBuffers::from(rt_film::AovSet::default()).with_variance();
        let (film, stats) = Renderer::new(&scene).render(&integrator, buffers, 2, 1);
        (invalid_values(&film), stats.discarded)
    });
    match result {
        Ok((0, 0)) => {}
        Ok((invalid, discarded)) => panic!(
            "a mutant of {} loads but renders {invalid} invalid values and discards {discarded} \
             samples:\n{text}",
            original.display()
        ),
        Err(_) => panic!(
            "a mutant of {} loads but its render panics:\n{text}",
            original.display()
        ),
    }
}

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
    let mut rng = Rng::new(0x9e37_79b9_7f4a_7c15);
    let (mut errors, mut tried, mut rendered) = (0, 0, 0);
    let mut paths: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    // read_dir's order is the file system's; the mutants must not depend on it.
    paths.sort();
    assert!(paths.len() >= 5, "the shipped scenes: {paths:?}");
    for path in paths {
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
            match result {
                Ok(loaded) => {
                    rendered += 1;
                    render_mutant(loaded.scene, &bad, &path);
                }
                Err(e) => {
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
    }
    // The mutations must actually exercise the error paths, and the render of loading ones.
    assert!(
        errors > tried / 3,
        "only {errors} of {tried} mutants were rejected"
    );
    assert!(
        rendered > tried / 10,
        "only {rendered} of {tried} mutants loaded"
    );
}
