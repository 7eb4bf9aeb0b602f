//! `render --confine DIR`: a scene that refers to a file outside DIR (directly, through `..`,
//! through a material library of a mesh inside, or through a symbolic link) is refused with one
//! line naming the file, before it is read; the same scenes render without the flag, and a
//! scene whose files are all inside renders with it.

mod common;

use common::{one_error_line, render};
use std::path::Path;

const TRIANGLE: &str = "mtllib m.mtl\nv -1 0 -1\nv 1 0 -1\nv 0 0 1\nusemtl grey\nf 1 2 3\n";
const MTL: &str = "newmtl grey\nKd 0.5 0.5 0.5\n";

fn scene(dir: &Path, mesh: &str) {
    let toml = format!(
        "[[camera]]\nname = \"c\"\nposition = [0, 2, 0.1]\nlook_at = [0, 0, 0]\nresolution = [8, 6]\n\n\
         [environment]\ncolor = [1, 1, 1]\n\n\
         [[geometry]]\nname = \"m\"\nfile = \"{mesh}\"\n"
    );
    std::fs::write(dir.join("s.toml"), toml).unwrap();
}

#[test]
fn files_outside_the_confinement_are_refused_before_they_are_read() {
    let d = tempfile::tempdir().unwrap();
    let root = d.path();
    let farm = root.join("farm");
    std::fs::create_dir_all(farm.join("sub")).unwrap();
    std::fs::write(root.join("outside.obj"), TRIANGLE).unwrap();
    std::fs::write(root.join("m.mtl"), MTL).unwrap();
    std::fs::write(farm.join("m.mtl"), MTL).unwrap();
    std::fs::write(farm.join("inside.obj"), TRIANGLE).unwrap();
    // A mesh inside whose material library is outside.
    std::fs::write(
        farm.join("sub/leaky.obj"),
        TRIANGLE.replace("mtllib m.mtl", "mtllib ../../m.mtl"),
    )
    .unwrap();
    let confined = |scene_dir: &Path| {
        render(
            scene_dir,
            &[
                "s.toml",
                "--spp",
                "1",
                "-q",
                "--confine",
                farm.to_str().unwrap(),
                "-o",
                "x.exr",
            ],
        )
    };
    let free = |scene_dir: &Path| render(scene_dir, &["s.toml", "--spp", "1", "-q", "-o", "x.exr"]);

    // All inside: renders.
    scene(&farm, "inside.obj");
    let o = confined(&farm);
    assert!(o.status.success(), "{o:?}");

    for (mesh, refused) in [
        ("../outside.obj", "outside.obj"),
        ("sub/leaky.obj", "m.mtl"),
    ] {
        scene(&farm, mesh);
        let e = one_error_line(&confined(&farm));
        assert!(e.contains("refused: the file is outside"), "{mesh}: {e}");
        assert!(e.contains(refused), "{mesh}: {e}");
        assert!(e.contains("--confine"), "{e}");
        // The control: without --confine the same scene renders.
        let o = free(&farm);
        assert!(o.status.success(), "{mesh}: {o:?}");
    }

    // A symbolic link inside the directory that points out of it.
    #[cfg(unix)]
    {
        std::os::unix::fs::symlink(root.join("outside.obj"), farm.join("link.obj")).unwrap();
        scene(&farm, "link.obj");
        let e = one_error_line(&confined(&farm));
        assert!(e.contains("link.obj") && e.contains("outside.obj"), "{e}");
    }

    // The scene file itself outside.
    scene(root, "farm/inside.obj");
    let e = one_error_line(&confined(root));
    assert!(e.contains("s.toml"), "{e}");

    // A confinement directory that does not exist.
    let o = render(
        &farm,
        &[
            "s.toml",
            "--confine",
            root.join("none").to_str().unwrap(),
            "-o",
            "x.exr",
        ],
    );
    let e = one_error_line(&o);
    assert!(e.contains("--confine"), "{e}");
}

#[test]
fn reference_experiment_and_plan_are_confined_too() {
    let d = tempfile::tempdir().unwrap();
    let root = d.path();
    let farm = root.join("farm");
    std::fs::create_dir_all(&farm).unwrap();
    std::fs::write(root.join("outside.obj"), TRIANGLE).unwrap();
    std::fs::write(root.join("m.mtl"), MTL).unwrap();
    scene(&farm, "../outside.obj");
    std::fs::write(
        farm.join("x.toml"),
        "name = \"x\"\n[[scene]]\nname = \"s\"\npath = \"s.toml\"\nreference = { spp = 4 }\n[[method]]\nname = \"p\"\nintegrator = \"path\"\nspp = [1]\n",
    )
    .unwrap();
    let farm_s = farm.display().to_string();
    for args in [
        vec!["reference", "s.toml", "--spp", "4", "--confine", &farm_s],
        vec!["experiment", "x.toml", "--check", "--confine", &farm_s],
        vec!["plan", "s.toml", "--confine", &farm_s, "-o", "p.json"],
        vec![
            "plan",
            "x.toml",
            "--experiment",
            "--confine",
            &farm_s,
            "-o",
            "p.json",
        ],
    ] {
        let e = one_error_line(&render(&farm, &args));
        assert!(
            e.contains("outside.obj") && e.contains("refused"),
            "{args:?}: {e}"
        );
    }
    // Without the flag, the same files load.
    let out = render(&farm, &["experiment", "x.toml", "--check"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}
