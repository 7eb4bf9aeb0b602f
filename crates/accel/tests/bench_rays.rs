//! `rt_accel::bench`: the uniform ray set's distribution and the `.bin` round trip.

use rt_accel::bench::{
    decode, encode, read_rays, read_set, uniform, write_rays, FormatError, Query, RayFileError,
    RAY_BYTES,
};
use rt_core::{glam::Vec3, Aabb, Ray};

const N: usize = 200_000;

fn bounds() -> Aabb {
    Aabb::new(Vec3::new(-3.0, 0.5, 10.0), Vec3::new(1.0, 0.75, 40.0))
}

#[test]
fn uniform_rays_are_deterministic_for_a_seed() {
    let a = uniform(&bounds(), 1000, 42);
    assert_eq!(a, uniform(&bounds(), 1000, 42));
    assert_eq!(a.query, Query::Closest);
    let b = uniform(&bounds(), 1000, 43);
    assert!(a.rays.iter().zip(&b.rays).all(|(x, y)| x != y));
    // A prefix does not depend on the count (each ray is a function of seed and index).
    assert_eq!(uniform(&bounds(), 10, 42).rays, a.rays[..10]);
}

#[test]
fn uniform_origins_fill_the_box_and_directions_cover_the_sphere_without_bias() {
    let b = bounds();
    let set = uniform(&b, N, 1);
    assert_eq!(set.rays.len(), N);
    let n = N as f64;
    let mut sum_dir = [0f64; 3];
    let mut sum_origin = [0f64; 3];
    let mut octants = [0usize; 8];
    for r in &set.rays {
        assert!(b.contains(r.origin), "origin {} outside the box", r.origin);
        assert!(
            (r.dir.length() - 1.0).abs() < 1e-5,
            "direction {} not unit",
            r.dir
        );
        for k in 0..3 {
            sum_dir[k] += r.dir[k] as f64;
            sum_origin[k] += ((r.origin[k] - b.min[k]) / (b.max[k] - b.min[k])) as f64;
        }
        let o = (r.dir.x > 0.0) as usize
            | ((r.dir.y > 0.0) as usize) << 1
            | ((r.dir.z > 0.0) as usize) << 2;
        octants[o] += 1;
    }
    // A unit vector uniform on the sphere has E[d_k] = 0 and Var[d_k] = 1/3, so the mean of N
    // has standard deviation sqrt(1 / (3N)); allow 5 of them. The origins' relative coordinates
    // are uniform on [0, 1]: mean 1/2, variance 1/12.
    let sd_dir = (1.0 / (3.0 * n)).sqrt();
    let sd_origin = (1.0 / (12.0 * n)).sqrt();
    for k in 0..3 {
        let m = sum_dir[k] / n;
        assert!(
            m.abs() < 5.0 * sd_dir,
            "mean direction[{k}] = {m} (sd {sd_dir})"
        );
        let m = sum_origin[k] / n;
        assert!(
            (m - 0.5).abs() < 5.0 * sd_origin,
            "mean origin[{k}] = {m} (sd {sd_origin})"
        );
    }
    // Every octant gets 1/8 of the directions (binomial sd sqrt(N p (1 - p))).
    let sd_oct = (n * (1.0 / 8.0) * (7.0 / 8.0)).sqrt();
    for (i, &c) in octants.iter().enumerate() {
        assert!(
            (c as f64 - n / 8.0).abs() < 5.0 * sd_oct,
            "octant {i}: {c} of {N}"
        );
    }
}

#[test]
fn ray_files_round_trip() {
    let rays = vec![
        Ray::new(Vec3::new(0.5, -1.0, 2.0), Vec3::new(0.0, 0.0, -1.0)),
        Ray::new(Vec3::new(1e-7, 3e5, -0.0), Vec3::new(0.3, -0.2, 0.1)),
    ];
    let bytes = encode(&rays);
    assert_eq!(bytes.len(), 2 * RAY_BYTES);
    assert_eq!(decode(&bytes).unwrap(), rays);
    let set = uniform(&bounds(), 5000, 9);
    assert_eq!(decode(&encode(&set.rays)).unwrap(), set.rays);

    let dir = std::env::temp_dir().join(format!("rt-accel-bench-rays-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("uniform.bin");
    write_rays(&path, &set.rays).unwrap();
    let back = read_set(&path, "uniform", Query::Closest).unwrap();
    assert_eq!(back, set);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn corrupted_or_truncated_ray_files_give_typed_errors() {
    let rays = uniform(&bounds(), 10, 3).rays;
    let bytes = encode(&rays);
    assert_eq!(decode(&[]), Err(FormatError::Empty));
    for cut in [1, 23, 25, 239] {
        assert_eq!(decode(&bytes[..cut]), Err(FormatError::Size { len: cut }));
    }
    let mut nan = bytes.clone();
    nan[2 * RAY_BYTES + 20..2 * RAY_BYTES + 24].copy_from_slice(&f32::NAN.to_le_bytes());
    assert!(matches!(
        decode(&nan),
        Err(FormatError::NonFinite { index: 2, .. })
    ));
    let mut inf = bytes.clone();
    inf[4..8].copy_from_slice(&f32::INFINITY.to_le_bytes());
    assert!(matches!(
        decode(&inf),
        Err(FormatError::NonFinite { index: 0, .. })
    ));
    let mut zero = bytes.clone();
    zero[5 * RAY_BYTES + 12..6 * RAY_BYTES].fill(0);
    assert_eq!(decode(&zero), Err(FormatError::ZeroDirection { index: 5 }));

    // Through the file reader, with the path in the message.
    let dir = std::env::temp_dir().join(format!("rt-accel-bench-bad-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let odd = dir.join("odd.bin");
    std::fs::write(&odd, &bytes[..25]).unwrap();
    let err = read_rays(&odd).unwrap_err();
    assert!(matches!(
        err,
        RayFileError::Format {
            source: FormatError::Size { len: 25 },
            ..
        }
    ));
    let text = err.to_string();
    assert!(
        text.contains("odd.bin") && text.contains("multiple of 24"),
        "{text}"
    );
    let missing = read_rays(&dir.join("missing.bin")).unwrap_err();
    assert!(matches!(missing, RayFileError::Io { .. }), "{missing}");
    std::fs::remove_dir_all(&dir).unwrap();
}
