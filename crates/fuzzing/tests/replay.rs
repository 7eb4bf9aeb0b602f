//! Every input of the committed seeds and corpus (`fuzz/seeds/<target>/`: valid files of each
//! format and the crashes campaigns found, named `crash-*`; `fuzz/corpus/<target>/`: what
//! campaigns kept, minimized) through its target: a panic fails the test, naming the file.
//! This is how CI runs the fuzz targets (the campaigns themselves run outside CI:
//! docs/testing.md, "Fuzzing").
//!
//! The bounds of a campaign hold here too: an input that takes longer than [`TIMEOUT`]
//! (libFuzzer's `-timeout=10`) fails the test naming the file, and an allocation that would
//! take the process's live heap past [`MEMORY_LIMIT`] (`-rss_limit_mb=2048`) aborts it with a
//! line naming the input being replayed. A seed or corpus folder that is missing or empty fails
//! too: a replay of nothing would pass.

use std::alloc::{GlobalAlloc, Layout, System};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering::Relaxed};
use std::sync::mpsc;
use std::sync::Mutex;
use std::time::Duration;

/// Longest one input may take (libFuzzer's `-timeout` of the campaigns).
const TIMEOUT: Duration = Duration::from_secs(10);
/// Largest live heap of the test process (the campaigns' `-rss_limit_mb=2048`).
const MEMORY_LIMIT: usize = 2 << 30;

/// The system allocator, refusing to let the live heap pass [`MEMORY_LIMIT`].
struct Bounded;

static LIVE: AtomicUsize = AtomicUsize::new(0);
/// The input being replayed, for the message of an allocation over the limit.
static CURRENT: Mutex<String> = Mutex::new(String::new());

// SAFETY: every call is forwarded to `System` with the caller's arguments; the counter only
// decides whether to forward an allocation or abort.
unsafe impl GlobalAlloc for Bounded {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        over_limit(layout.size());
        // SAFETY: the caller's contract for `GlobalAlloc::alloc` is passed on unchanged.
        unsafe { System.alloc(layout) }
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        over_limit(layout.size());
        // SAFETY: as in `alloc`.
        unsafe { System.alloc_zeroed(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        LIVE.fetch_sub(layout.size(), Relaxed);
        // SAFETY: `ptr` came from `System` with this layout (every allocation goes through here).
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        over_limit(new_size);
        LIVE.fetch_sub(layout.size(), Relaxed);
        // SAFETY: as in `dealloc` and `alloc`.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

/// Counts `size` more live bytes; past the limit, names the input and aborts (a panic here
/// would allocate).
fn over_limit(size: usize) {
    let live = LIVE.fetch_add(size, Relaxed).saturating_add(size);
    if live > MEMORY_LIMIT {
        let mut err = std::io::stderr().lock();
        let _ = err.write_all(b"fuzz replay: the live heap would pass 2 GiB while replaying ");
        if let Ok(name) = CURRENT.try_lock() {
            let _ = err.write_all(name.as_bytes());
        }
        let _ = err.write_all(b"\n");
        std::process::abort();
    }
}

#[global_allocator]
static ALLOCATOR: Bounded = Bounded;

fn fuzz_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fuzz")
}

/// The files of `dir`, sorted.
///
/// # Panics
/// If `dir` cannot be read or holds no file: every target has seeds and a corpus, and a folder
/// that went missing must not replay as empty.
fn files(dir: &Path) -> Vec<PathBuf> {
    let entries = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: cannot read the folder: {e}", dir.display()));
    let mut v: Vec<PathBuf> = entries
        .map(|e| e.expect("a directory entry").path())
        .collect();
    v.sort();
    assert!(!v.is_empty(), "{} is empty", dir.display());
    v
}

/// Runs `target` on each file on one worker thread and fails, naming the file, if one panics
/// or takes longer than `timeout`. Returns how many were replayed.
fn replay(
    name: &str,
    target: rt_fuzzing::Target,
    inputs: Vec<PathBuf>,
    timeout: Duration,
) -> usize {
    let (to_worker, work) = mpsc::channel::<Vec<u8>>();
    let (done, from_worker) = mpsc::channel::<bool>();
    let worker = std::thread::spawn(move || {
        for data in work {
            let ok = std::panic::catch_unwind(|| target(&data)).is_ok();
            if done.send(ok).is_err() {
                return;
            }
        }
    });
    let n = inputs.len();
    for file in inputs {
        *CURRENT.lock().unwrap() = format!("{name}: {}", file.display());
        to_worker.send(std::fs::read(&file).unwrap()).unwrap();
        match from_worker.recv_timeout(timeout) {
            Ok(true) => {}
            Ok(false) => panic!("{name}: {} panics", file.display()),
            Err(_) => panic!(
                "{name}: {} takes longer than {timeout:?} (a hang, or work sized by a field of the file)",
                file.display()
            ),
        }
    }
    drop(to_worker);
    worker.join().unwrap();
    n
}

#[test]
fn the_seeds_and_the_corpus_load_without_a_panic() {
    let mut inputs = 0;
    for (name, target) in rt_fuzzing::TARGETS {
        let mut all = files(&fuzz_dir().join("seeds").join(name));
        all.extend(files(&fuzz_dir().join("corpus").join(name)));
        inputs += replay(name, target, all, TIMEOUT);
    }
    println!("{inputs} inputs replayed");
}

/// The bounds themselves: a target that panics or hangs fails naming the file, and a missing
/// or empty folder is an error, not an empty list.
#[test]
fn a_panic_a_hang_and_a_missing_folder_fail() {
    fn message<T>(r: std::thread::Result<T>) -> String {
        match r {
            Ok(_) => panic!("no failure"),
            Err(e) => *e.downcast::<String>().unwrap(),
        }
    }
    let d = tempfile::tempdir().unwrap();
    let f = d.path().join("input");
    std::fs::write(&f, b"x").unwrap();
    let short = Duration::from_millis(100);
    let m = message(std::panic::catch_unwind(|| {
        replay("t", |_| panic!("boom"), vec![f.clone()], TIMEOUT)
    }));
    assert!(m.ends_with("input panics"), "{m}");
    let m = message(std::panic::catch_unwind(|| {
        replay(
            "t",
            |_| std::thread::sleep(Duration::from_secs(1)),
            vec![f.clone()],
            short,
        )
    }));
    assert!(m.contains("input takes longer than 100ms"), "{m}");
    let m = message(std::panic::catch_unwind(|| files(&d.path().join("absent"))));
    assert!(m.contains("absent: cannot read the folder"), "{m}");
    let empty = d.path().join("empty");
    std::fs::create_dir(&empty).unwrap();
    let m = message(std::panic::catch_unwind(|| files(&empty)));
    assert!(m.ends_with("empty is empty"), "{m}");
}

/// Run by [`an_allocation_past_the_limit_aborts_naming_the_input`] in a child process: one
/// input whose target allocates 3 GiB.
#[test]
#[ignore = "run in a child process by an_allocation_past_the_limit_aborts_naming_the_input"]
fn allocation_probe() {
    let d = tempfile::tempdir().unwrap();
    let f = d.path().join("huge-claim");
    std::fs::write(&f, b"x").unwrap();
    let greedy: rt_fuzzing::Target = |_| {
        std::hint::black_box(vec![0u8; 3 << 30]);
    };
    replay("probe", greedy, vec![f], TIMEOUT);
}

#[test]
fn an_allocation_past_the_limit_aborts_naming_the_input() {
    let out = std::process::Command::new(std::env::current_exe().unwrap())
        .args(["--exact", "allocation_probe", "--ignored", "--nocapture"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "the probe passed: {err}");
    assert!(
        err.contains("the live heap would pass 2 GiB while replaying probe: ")
            && err.contains("huge-claim"),
        "{err}"
    );
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
