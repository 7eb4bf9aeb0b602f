//! report.html in a real browser: a tiny experiment (the Cornell box at 32×24, a few samples
//! per pixel, one plain and one `box`-denoised method) is run, and its page is opened in
//! Debian's headless Chromium.
//!
//! How: a copy of report.html beside it (so every relative link resolves the same) gets
//! `html_check.js` injected at the top of its `<head>`. That script records console errors and
//! warnings, failed loads and script errors from the start; after the load event it checks that
//! every `<img>` has loaded (`complete` and `naturalWidth > 0`), and, in every viewer, that the
//! keys 1, 2, ArrowRight and ArrowLeft and a button click show exactly the picture they should,
//! that the wheel zooms and that switching keeps the zoom. It writes its findings into
//! `<pre id="rt-check">`; `chromium --headless=new --dump-dom --virtual-time-budget=...`
//! prints the DOM after load, and the test reads the findings from it. No WebDriver, no
//! DevTools client: one process per page.
//!
//! Controls: the same check must report a deleted picture, and a page whose key handler is
//! disconnected.
//!
//! Without Chromium the test prints a note and passes, unless `RT_REQUIRE_DATA=1` (as in CI,
//! whose `.ci/setup` installs it), where it fails.

use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const CHECK_SCRIPT: &str = include_str!("html_check.js");

/// How long one page may take in the browser, wall clock.
const BROWSER_TIMEOUT: Duration = Duration::from_secs(120);

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Chromium's executable: `RT_CHROMIUM`, or the first of Debian's names on the PATH.
fn chromium() -> Option<PathBuf> {
    if let Some(p) = std::env::var_os("RT_CHROMIUM") {
        return Some(PathBuf::from(p));
    }
    let path = std::env::var_os("PATH")?;
    ["chromium", "chromium-browser", "google-chrome"]
        .iter()
        .flat_map(|name| std::env::split_paths(&path).map(move |d| d.join(name)))
        .find(|p| p.is_file())
}

/// What the in-page check found.
struct Findings {
    notes: Vec<String>,
    problems: Vec<String>,
}

fn unescape(t: &str) -> String {
    t.replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&quot;", "\"")
        .replace("&#39;", "'")
        .replace("&amp;", "&")
}

/// Opens `page` (an HTML file) with the check injected and returns what it found. Panics when
/// the browser does not run or the check's output is missing (a page that never loads).
fn check_page(browser: &Path, page: &Path) -> Findings {
    let html = std::fs::read_to_string(page).unwrap();
    assert_eq!(html.matches("<head>").count(), 1, "one <head> in {page:?}");
    let checked = page.with_file_name("report-check.html");
    std::fs::write(
        &checked,
        html.replace(
            "<head>",
            &format!("<head>\n<script>\n{CHECK_SCRIPT}</script>"),
        ),
    )
    .unwrap();
    let profile = tempfile::tempdir().unwrap();
    let url = format!("file://{}", checked.canonicalize().unwrap().display());
    let mut child = Command::new(browser)
        .args([
            "--headless=new",
            // Root in a container has no user namespaces for the sandbox; the page is ours.
            "--no-sandbox",
            "--disable-gpu",
            "--no-first-run",
            "--disable-extensions",
            "--window-size=1280,900",
            "--virtual-time-budget=10000",
            "--dump-dom",
        ])
        .arg(format!("--user-data-dir={}", profile.path().display()))
        .arg(&url)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap_or_else(|e| panic!("cannot start {browser:?}: {e}"));
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > BROWSER_TIMEOUT {
            let _ = child.kill();
            panic!("{browser:?} did not finish {url} within {BROWSER_TIMEOUT:?}");
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    let out = child.wait_with_output().unwrap();
    let dom = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    let start_tag = "<pre id=\"rt-check\">";
    // The last one: the injected script itself names the tag in a comment.
    let Some(at) = dom.rfind(start_tag) else {
        panic!(
            "no check output in the DOM of {url} (exit {:?})\nstderr:\n{stderr}\nDOM tail:\n{}",
            out.status,
            &dom[dom.len().saturating_sub(2000)..]
        );
    };
    let body = &dom[at + start_tag.len()..];
    let body = unescape(&body[..body.find("</pre>").expect("closed <pre>")]);
    assert!(body.ends_with("END"), "truncated check output: {body}");
    let mut f = Findings {
        notes: Vec::new(),
        problems: Vec::new(),
    };
    for line in body.lines().filter(|l| *l != "END") {
        match line.strip_prefix("PROBLEM ") {
            Some(p) => f.problems.push(p.to_string()),
            None => f.notes.push(line.to_string()),
        }
    }
    f
}

const CONFIG: &str = r#"
name = "html"

[[scene]]
name = "cornell"
path = "SCENES/cornell-box.toml"
resolution = [32, 24]
reference = { spp = 16, max_depth = 3 }

[[method]]
name = "path"
max_depth = 3
spp = [1, 2, 4]

[[method]]
name = "path-box"
max_depth = 3
spp = [1, 2, 4]
denoiser = "box:radius=1"
"#;

#[test]
fn report_html_loads_every_image_and_switches_in_chromium() {
    let required = std::env::var("RT_REQUIRE_DATA").is_ok_and(|v| v == "1");
    let browser = chromium();
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("html.toml");
    let scenes = repo().join("scenes").canonicalize().unwrap();
    std::fs::write(
        &config,
        CONFIG.replace("SCENES", &scenes.display().to_string()),
    )
    .unwrap();
    let plan = rt_experiment::config::load(&config).unwrap();
    // RT_HTML_TEST_OUT=DIR keeps the experiment (DIR must not exist or be empty) to look at.
    let out = std::env::var_os("RT_HTML_TEST_OUT")
        .map(PathBuf::from)
        .unwrap_or_else(|| dir.path().join("out"));
    rt_experiment::prepare_out(&out).unwrap();
    let cache = rt_experiment::Cache::new(&dir.path().join("cache"));
    let outcome = rt_experiment::run(&plan, &out, &cache, &rt_experiment::Silent).unwrap();
    let html = std::fs::read_to_string(&outcome.html).unwrap();

    // Without a browser: every local link of the page names a file in the folder.
    let mut links = 0;
    for attr in ["src=\"", "href=\""] {
        for part in html.split(attr).skip(1) {
            let target = unescape(&part[..part.find('"').unwrap()]);
            if target.starts_with('#') {
                continue;
            }
            assert!(
                !target.contains("://") && !target.starts_with('/'),
                "not a relative link: {target}"
            );
            assert!(out.join(&target).is_file(), "{target} is missing");
            links += 1;
        }
    }
    // Two plots, the reference, the denoised method's noisy input, two finals, two errors,
    // three data files.
    assert_eq!(links, 2 + 1 + 1 + 2 + 2 + 3, "{html}");

    let Some(browser) = browser else {
        assert!(
            !required,
            "RT_REQUIRE_DATA=1 but Chromium is not installed (.ci/setup installs it: apt-get install chromium)"
        );
        // Past libtest's capture, as rt_validate::data::skip does, so the note shows.
        let _ = std::io::stderr().lock().write_all(
            b"skipping: report.html in a browser: Chromium not found (apt-get install chromium; \
              set RT_REQUIRE_DATA=1 to make this a failure)\n",
        );
        return;
    };

    let f = check_page(&browser, &outcome.html);
    assert!(f.problems.is_empty(), "{:#?}", f.problems);
    assert!(f.notes.contains(&"images 8".to_string()), "{:?}", f.notes);
    assert!(f.notes.contains(&"viewers 1".to_string()), "{:?}", f.notes);
    assert!(
        f.notes.contains(&"viewer 1 pictures 6".to_string()),
        "{:?}",
        f.notes
    );
    eprintln!("report.html in Chromium: {:?}", f.notes);

    // Control: a missing picture is found.
    let victim = out.join("view/cornell/path-box/error.png");
    let aside = out.join("aside.png");
    std::fs::rename(&victim, &aside).unwrap();
    let f = check_page(&browser, &outcome.html);
    eprintln!("control, a deleted picture: {:#?}", f.problems);
    assert!(
        f.problems
            .iter()
            .any(|p| p.starts_with("image not shown")
                && p.ends_with("view/cornell/path-box/error.png")),
        "{:#?}",
        f.problems
    );
    assert!(
        f.problems
            .iter()
            .any(|p| p.starts_with("failed to load") && p.ends_with("path-box/error.png")),
        "{:#?}",
        f.problems
    );

    std::fs::rename(&aside, &victim).unwrap();

    // Control: a page whose key handler is gone does not switch.
    let broken = out.join("broken.html");
    std::fs::write(
        &broken,
        html.replace(
            "document.addEventListener(\"keydown\"",
            "document.addEventListener(\"keydown-disconnected\"",
        ),
    )
    .unwrap();
    let f = check_page(&browser, &broken);
    eprintln!("control, no key handler: {:#?}", f.problems);
    assert!(
        !f.problems.iter().any(|p| p.contains("image")),
        "{:#?}",
        f.problems
    );
    assert!(
        f.problems
            .iter()
            .any(|p| p.contains("key 2 did not show the second picture")),
        "{:#?}",
        f.problems
    );
}
