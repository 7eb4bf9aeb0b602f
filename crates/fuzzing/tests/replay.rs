//! Every input of the committed seeds and corpus (`fuzz/seeds/<target>/`: valid files of each
//! format and the crashes campaigns found, named `crash-*`; `fuzz/corpus/<target>/`: what
//! campaigns kept, minimized) through its target: a panic fails the test, naming the file.
//! This is how CI runs the fuzz targets (the campaigns themselves run outside CI:
//! docs/testing.md, "Fuzzing").

use std::path::{Path, PathBuf};

fn fuzz_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fuzz")
}

/// The files of `dir`, sorted; none if it does not exist.
fn files(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = match std::fs::read_dir(dir) {
        Ok(entries) => entries.filter_map(|e| Some(e.ok()?.path())).collect(),
        Err(_) => Vec::new(),
    };
    v.sort();
    v
}

#[test]
fn the_seeds_and_the_corpus_load_without_a_panic() {
    let mut inputs = 0;
    for (name, target) in rt_fuzzing::TARGETS {
        let seeds = files(&fuzz_dir().join("seeds").join(name));
        assert!(!seeds.is_empty(), "fuzz/seeds/{name} is empty");
        for file in seeds
            .into_iter()
            .chain(files(&fuzz_dir().join("corpus").join(name)))
        {
            let data = std::fs::read(&file).unwrap();
            let outcome = std::panic::catch_unwind(|| target(&data));
            assert!(outcome.is_ok(), "{name}: {} panics", file.display());
            inputs += 1;
        }
    }
    println!("{inputs} inputs replayed");
}

#[test]
fn the_seeds_are_valid_inputs_of_their_loaders() {
    // The seeds must reach deep into their formats: each loads without error where it is
    // self-contained (an invalid seed would leave the fuzzer at the parser's door).
    let seeds = fuzz_dir().join("seeds");
    for (dir, ext) in [
        ("obj", "obj"),
        ("gltf", "gltf"),
        ("glb", "glb"),
        ("ra2", "ra2"),
    ] {
        let d = tempfile::tempdir().unwrap();
        for f in files(&seeds.join(dir)) {
            if f.file_name()
                .unwrap()
                .to_string_lossy()
                .starts_with("crash-")
            {
                continue;
            }
            let p = d.path().join(format!("m.{ext}"));
            std::fs::copy(&f, &p).unwrap();
            rt_scene::load_mesh(&p).unwrap_or_else(|e| panic!("{}: {e}", f.display()));
        }
    }
    rt_film::read_rgb(&seeds.join("exr/tiny.exr")).unwrap();
    rt_film::decode_srgb(&std::fs::read(seeds.join("image/checker.png")).unwrap()).unwrap();
    // Part files and checkpoints as `render` writes them (by this build: the format is
    // versioned), each merging alone into its film.
    for f in files(&seeds.join("part")) {
        let part = rt_parts::Part::from_bytes(&std::fs::read(&f).unwrap())
            .unwrap_or_else(|e| panic!("{}: {e}", f.display()));
        let mut whole = part.clone();
        whole.header.samples[0] = 0;
        whole.header.samples[1] = whole.header.spp;
        let r = part.header.rect();
        if (r.width(), r.height()) == (whole.header.width, whole.header.height) {
            rt_parts::merge(&[("seed".into(), whole)], None)
                .unwrap_or_else(|e| panic!("{}: {e}", f.display()));
        }
    }
    for f in files(&seeds.join("plan")) {
        rt_parts::Plan::from_json(&std::fs::read_to_string(&f).unwrap())
            .unwrap_or_else(|e| panic!("{}: {e}", f.display()));
    }
}

#[test]
fn the_crashes_campaigns_found_are_now_one_clear_error() {
    let seeds = fuzz_dir().join("seeds");
    let d = tempfile::tempdir().unwrap();
    let copy = |from: &str, name: &str| {
        let p = d.path().join(name);
        std::fs::copy(seeds.join(from), &p).unwrap();
        p
    };
    // gltf-json's validation indexed POSITION's accessor before checking it.
    let e = rt_scene::load_mesh(&copy("gltf/crash-position-accessor-out-of-range", "a.gltf"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("names accessor 4, but there are 4"), "{e}");
    // The gltf crate's index reader hit `unreachable!` on signed indices.
    let e = rt_scene::load_mesh(&copy("glb/crash-float-indices", "b.glb"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("indices must be unsigned integer scalars"),
        "{e}"
    );
    // The exr crate allocated the 13 TB a 580-byte header claimed.
    let e = rt_film::read_exr(&copy("exr/crash-exr-claims-13tb", "c.exr"))
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("more than a 580-byte file can hold"), "{e}");
}
