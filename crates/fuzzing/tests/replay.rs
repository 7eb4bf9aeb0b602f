//! Every input of the committed corpus (`fuzz/corpus/<target>/`: the seeds, what campaigns
//! kept, and the crashes they found, named `crash-*`) through its target: a panic fails the
//! test, naming the file. This is how CI runs the fuzz targets (the campaigns themselves run
//! outside CI: docs/testing.md, "Fuzzing").

use std::path::Path;

#[test]
fn the_corpus_loads_without_a_panic() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fuzz/corpus");
    let mut inputs = 0;
    for (name, target) in rt_fuzzing::TARGETS {
        let dir = root.join(name);
        let mut files: Vec<_> = std::fs::read_dir(&dir)
            .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
            .map(|e| e.unwrap().path())
            .collect();
        files.sort();
        assert!(!files.is_empty(), "{} has no seeds", dir.display());
        for file in files {
            let data = std::fs::read(&file).unwrap();
            let outcome = std::panic::catch_unwind(|| target(&data));
            assert!(outcome.is_ok(), "{name}: {} panics", file.display());
            inputs += 1;
        }
    }
    println!("{inputs} corpus inputs replayed");
}

#[test]
fn the_seeds_are_valid_inputs_of_their_loaders() {
    // The seeds must reach deep into their formats: each loads without error where it is
    // self-contained (an invalid seed would leave the fuzzer at the parser's door).
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fuzz/corpus");
    for (dir, ext) in [
        ("obj", "obj"),
        ("gltf", "gltf"),
        ("glb", "glb"),
        ("ra2", "ra2"),
    ] {
        let d = tempfile::tempdir().unwrap();
        for f in std::fs::read_dir(root.join(dir)).unwrap() {
            let f = f.unwrap().path();
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
    rt_film::read_rgb(&root.join("exr/tiny.exr")).unwrap();
    rt_film::decode_srgb(&std::fs::read(root.join("image/checker.png")).unwrap()).unwrap();
}
