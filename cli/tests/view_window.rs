//! `render view`'s window on a virtual X server (Xvfb): it opens at the asked size, shows a
//! rendered image (a screenshot of its region is neither uniform nor black), puts frames per
//! second in its title, zooms out on the mouse wheel (synthetic XTEST events), and exits 0
//! when the window is closed (WM_DELETE_WINDOW, as a window manager's close button sends it).
//!
//! Xvfb is installed by `.ci/setup`; without it the test fails unless `RT_SKIP_XVFB=1`, in
//! which case it prints `skipping: ...` and passes. The screenshot is taken over the X protocol (x11rb,
//! pure Rust) and saved as `view_window.png` under the target's test temp dir.

use std::io::{BufRead, BufReader, Write};
use std::path::PathBuf;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};
use x11rb::connection::Connection;
use x11rb::protocol::xproto::{
    self, AtomEnum, ClientMessageEvent, ConnectionExt, EventMask, ImageFormat, MapState, Window,
};
use x11rb::protocol::xtest;
use x11rb::rust_connection::RustConnection;

const SIZE: u16 = 256;
/// How long the viewer may take to show a rendered frame on a loaded machine.
const PATIENCE: Duration = Duration::from_secs(25);

/// Kills its processes by pid when dropped, so a failed assertion leaves nothing running.
struct Kill(Vec<Child>);

impl Drop for Kill {
    fn drop(&mut self) {
        for c in self.0.iter_mut().rev() {
            let _ = c.kill();
            let _ = c.wait();
        }
    }
}

fn find_in_path(name: &str) -> Option<PathBuf> {
    std::env::split_paths(&std::env::var_os("PATH")?)
        .map(|d| d.join(name))
        .find(|p| p.is_file())
}

/// The viewed mapped top-level window of `SIZE` x `SIZE`, if there is one yet.
fn viewer_window(conn: &RustConnection, root: Window) -> Option<(Window, i16, i16)> {
    let tree = conn.query_tree(root).ok()?.reply().ok()?;
    tree.children.into_iter().find_map(|w| {
        let attrs = conn.get_window_attributes(w).ok()?.reply().ok()?;
        let g = conn.get_geometry(w).ok()?.reply().ok()?;
        (attrs.map_state == MapState::VIEWABLE && g.width == SIZE && g.height == SIZE)
            .then_some((w, g.x, g.y))
    })
}

/// The window's title (_NET_WM_NAME, else WM_NAME).
fn title(conn: &RustConnection, w: Window) -> String {
    let net = conn
        .intern_atom(false, b"_NET_WM_NAME")
        .unwrap()
        .reply()
        .unwrap()
        .atom;
    for atom in [net, AtomEnum::WM_NAME.into()] {
        let value = conn
            .get_property(false, w, atom, AtomEnum::ANY, 0, 1024)
            .unwrap()
            .reply()
            .unwrap()
            .value;
        if !value.is_empty() {
            return String::from_utf8_lossy(&value).into_owned();
        }
    }
    String::new()
}

/// The window's region of the root window as 8-bit RGB.
fn screenshot(conn: &RustConnection, root: Window, x: i16, y: i16) -> Vec<[u8; 3]> {
    let image = conn
        .get_image(ImageFormat::Z_PIXMAP, root, x, y, SIZE, SIZE, !0)
        .unwrap()
        .reply()
        .unwrap();
    assert_eq!(image.depth, 24, "Xvfb runs at depth 24");
    // Depth 24 is 32 bits per pixel, little-endian 0x00RRGGBB: bytes B, G, R, pad.
    image
        .data
        .chunks_exact(4)
        .map(|p| [p[2], p[1], p[0]])
        .collect()
}

/// Mean and standard deviation of the pixels' channel values.
fn mean_and_sd(pixels: &[[u8; 3]]) -> (f64, f64) {
    let values = pixels.iter().flatten().map(|&v| f64::from(v));
    let n = (pixels.len() * 3) as f64;
    let mean = values.clone().sum::<f64>() / n;
    let var = values.map(|v| (v - mean) * (v - mean)).sum::<f64>() / n;
    (mean, var.sqrt())
}

/// A virtual X server on a free display: its process (killed on drop) and the display name;
/// `None` (after printing why) where Xvfb is missing and `RT_SKIP_XVFB=1`.
fn xvfb() -> Option<(Kill, String)> {
    let Some(xvfb) = find_in_path("Xvfb") else {
        if std::env::var("RT_SKIP_XVFB").as_deref() == Ok("1") {
            // The real standard error: libtest captures the print! family.
            let _ = writeln!(
                std::io::stderr(),
                "skipping: Xvfb is not installed (RT_SKIP_XVFB=1)"
            );
            return None;
        }
        panic!("Xvfb is not installed: run .ci/setup (Debian package xvfb), or set RT_SKIP_XVFB=1 to skip");
    };
    // -displayfd: Xvfb picks a free display and prints its number once it accepts clients.
    let mut server = Command::new(xvfb)
        .args([
            "-displayfd",
            "1",
            "-screen",
            "0",
            "640x480x24",
            "-br",
            "-nolisten",
            "tcp",
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let stdout = server.stdout.take().unwrap();
    let procs = Kill(vec![server]);
    let mut line = String::new();
    BufReader::new(stdout).read_line(&mut line).unwrap();
    assert!(line.trim().parse::<u32>().is_ok(), "Xvfb printed {line:?}");
    Some((procs, format!(":{}", line.trim())))
}

#[test]
fn the_window_shows_a_rendered_image_and_closes_cleanly() {
    let Some((mut procs, display)) = xvfb() else {
        return;
    };

    let root = workspace_root();
    let viewer = Command::new(env!("CARGO_BIN_EXE_render"))
        .current_dir(&root)
        .args(["view", "scenes/animated.toml", "--size", "256x256"])
        .env("DISPLAY", &display)
        .env_remove("WAYLAND_DISPLAY")
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    procs.0.push(viewer);

    let (conn, screen) = x11rb::connect(Some(&display)).unwrap();
    let root_window = conn.setup().roots[screen].root;
    let started = Instant::now();
    let mut last = None;
    let passed = loop {
        if let Some(status) = procs.0[1].try_wait().unwrap() {
            let mut err = String::new();
            let _ = std::io::Read::read_to_string(procs.0[1].stderr.as_mut().unwrap(), &mut err);
            panic!("the viewer exited early ({status}): {err}");
        }
        if let Some((w, x, y)) = viewer_window(&conn, root_window) {
            let pixels = screenshot(&conn, root_window, x, y);
            let (mean, sd) = mean_and_sd(&pixels);
            let title = title(&conn, w);
            // A rendered frame: not black, not one colour; and the title has a measured rate.
            let has_fps = title.contains(" fps") && !title.contains(": - fps");
            last = Some((w, pixels, mean, sd, title.clone()));
            if mean > 10.0 && sd > 8.0 && has_fps {
                break true;
            }
        }
        if started.elapsed() > PATIENCE {
            break false;
        }
        std::thread::sleep(Duration::from_millis(250));
    };
    let Some((window, pixels, mean, sd, title)) = last else {
        panic!("no {SIZE}x{SIZE} window appeared within {PATIENCE:?}");
    };
    let png = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("view_window.png");
    image::RgbImage::from_raw(
        SIZE.into(),
        SIZE.into(),
        pixels.into_iter().flatten().collect(),
    )
    .unwrap()
    .save(&png)
    .unwrap();
    assert!(
        passed,
        "the window shows no rendered image: mean {mean:.1}, sd {sd:.1}, title {title:?} (screenshot {})",
        png.display()
    );
    println!(
        "screenshot mean {mean:.1}, sd {sd:.1}, title {title:?}: {}",
        png.display()
    );

    // The wheel zooms: forty lines out (XTEST button 5 over the window) put the camera at the
    // farthest distance, where the scene is a small patch in the dark environment, so the mean
    // falls well below what it was.
    let (wx, wy) = {
        let g = conn.get_geometry(window).unwrap().reply().unwrap();
        (g.x, g.y)
    };
    let centre = (wx + SIZE as i16 / 2, wy + SIZE as i16 / 2);
    fake_input(&conn, xproto::MOTION_NOTIFY_EVENT, 0, root_window, centre);
    for _ in 0..40 {
        fake_input(&conn, xproto::BUTTON_PRESS_EVENT, 5, root_window, centre);
        fake_input(&conn, xproto::BUTTON_RELEASE_EVENT, 5, root_window, centre);
    }
    conn.flush().unwrap();
    let zooming = Instant::now();
    let zoomed_mean = loop {
        let (m, _) = mean_and_sd(&screenshot(&conn, root_window, wx, wy));
        if m < 0.5 * mean || zooming.elapsed() > PATIENCE {
            break m;
        }
        std::thread::sleep(Duration::from_millis(250));
    };
    assert!(
        zoomed_mean < 0.5 * mean,
        "zooming out did not shrink the scene: mean {mean:.1} before, {zoomed_mean:.1} after"
    );

    // Close it as a window manager would; it must exit 0 on its own.
    let protocols = conn
        .intern_atom(false, b"WM_PROTOCOLS")
        .unwrap()
        .reply()
        .unwrap()
        .atom;
    let delete = conn
        .intern_atom(false, b"WM_DELETE_WINDOW")
        .unwrap()
        .reply()
        .unwrap()
        .atom;
    let event = ClientMessageEvent::new(32, window, protocols, [delete, 0, 0, 0, 0]);
    conn.send_event(false, window, EventMask::NO_EVENT, event)
        .unwrap();
    conn.flush().unwrap();
    let closing = Instant::now();
    let status = loop {
        if let Some(s) = procs.0[1].try_wait().unwrap() {
            break Some(s);
        }
        if closing.elapsed() > Duration::from_secs(10) {
            break None;
        }
        std::thread::sleep(Duration::from_millis(100));
    };
    // `procs` kills Xvfb (and the viewer, if it is still there) by pid.
    let status = status.expect("the viewer did not exit within 10 s of WM_DELETE_WINDOW");
    assert!(status.success(), "closing the window exited with {status}");
}

/// One synthetic input event (XTEST) at root position `at`.
fn fake_input(conn: &RustConnection, kind: u8, detail: u8, root: Window, at: (i16, i16)) {
    xtest::fake_input(conn, kind, detail, 0, root, at.0, at.1, 0).unwrap();
}

fn workspace_root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .unwrap()
        .to_path_buf()
}

/// Four emitting quadrants filling the view, black where they do not emit: every pixel inside
/// a quadrant sees only its emission, whatever the sample, so a frame is the same bits at any
/// frame number and seed except along the quadrants' edges.
const QUADRANTS: &str = r#"
[[camera]]
name = "c"
position = [0.0, 0.0, 2.0]
look_at = [0.0, 0.0, 0.0]
fov = 60.0
resolution = [256, 256]

[[material]]
name = "a"
color = [0.0, 0.0, 0.0]
emission = [0.8, 0.2, 0.1]
two_sided = true

[[material]]
name = "b"
color = [0.0, 0.0, 0.0]
emission = [0.1, 0.6, 0.2]
two_sided = true

[[material]]
name = "c"
color = [0.0, 0.0, 0.0]
emission = [0.2, 0.3, 0.9]
two_sided = true

[[material]]
name = "d"
color = [0.0, 0.0, 0.0]
emission = [0.5, 0.45, 0.4]
two_sided = true

[[geometry]]
name = "qa"
shape = "quad"
vertices = [[-2, 0, 0], [0, 0, 0], [0, 2, 0], [-2, 2, 0]]
material = "a"

[[geometry]]
name = "qb"
shape = "quad"
vertices = [[0, 0, 0], [2, 0, 0], [2, 2, 0], [0, 2, 0]]
material = "b"

[[geometry]]
name = "qc"
shape = "quad"
vertices = [[-2, -2, 0], [0, -2, 0], [0, 0, 0], [-2, 0, 0]]
material = "c"

[[geometry]]
name = "qd"
shape = "quad"
vertices = [[0, -2, 0], [2, -2, 0], [2, 0, 0], [0, 0, 0]]
material = "d"
"#;

/// The window shows what `render view --headless` writes: on the quadrants scene, every pixel
/// whose 3 × 3 neighbourhood in the headless PNG is one colour (all its samples see one
/// emitter, in any frame) has the same 8-bit value in the screenshot, and those are most of the
/// image. A window that tone-maps, orders channels or places the image differently fails.
#[test]
fn the_window_shows_the_headless_frame() {
    let Some((mut procs, display)) = xvfb() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("q.toml"), QUADRANTS).unwrap();
    let common = [
        "q.toml",
        "--size",
        "256x256",
        "--spp",
        "4",
        "--denoiser",
        "none",
    ];
    let out = Command::new(env!("CARGO_BIN_EXE_render"))
        .current_dir(d)
        .args([
            "view",
            "--headless",
            "--frames",
            "0..1",
            "-q",
            "-o",
            "h_{frame}.png",
        ])
        .args(common)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let headless = image::open(d.join("h_0.png")).unwrap().to_rgb8();
    let viewer = Command::new(env!("CARGO_BIN_EXE_render"))
        .current_dir(d)
        .arg("view")
        .args(common)
        .env("DISPLAY", &display)
        .env_remove("WAYLAND_DISPLAY")
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    procs.0.push(viewer);
    let (conn, screen) = x11rb::connect(Some(&display)).unwrap();
    let root_window = conn.setup().roots[screen].root;
    let n = SIZE as usize;
    // The pixels whose neighbourhood is one colour in the headless frame.
    let flat: Vec<usize> = (1..n - 1)
        .flat_map(|y| (1..n - 1).map(move |x| (x, y)))
        .filter(|&(x, y)| {
            let c = headless.get_pixel(x as u32, y as u32);
            (0..9).all(|k| headless.get_pixel((x + k % 3 - 1) as u32, (y + k / 3 - 1) as u32) == c)
        })
        .map(|(x, y)| y * n + x)
        .collect();
    assert!(flat.len() * 10 > n * n * 9, "{} flat pixels", flat.len());
    let started = Instant::now();
    let mismatched = loop {
        let shown =
            viewer_window(&conn, root_window).map(|(_, x, y)| screenshot(&conn, root_window, x, y));
        let bad = shown.map(|s| {
            flat.iter()
                .filter(|&&i| s[i] != headless.get_pixel((i % n) as u32, (i / n) as u32).0)
                .count()
        });
        if bad == Some(0) || started.elapsed() > PATIENCE {
            break bad;
        }
        std::thread::sleep(Duration::from_millis(250));
    };
    assert_eq!(
        mismatched,
        Some(0),
        "pixels of the window that differ from the headless frame (of {} compared)",
        flat.len()
    );
}
