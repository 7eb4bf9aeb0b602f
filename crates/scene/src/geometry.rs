//! `[[geometry]]`: picks the source (mesh file, inline shape, inline triangle mesh), checks its
//! keys, places the triangles with the transform, checks them, resolves materials and appends
//! them to the scene in file order.

use crate::desc::{GeometryDesc, TransformDesc, V3};
use crate::error::{Result, SceneError};
use crate::load::{finite3, Ctx};
use crate::material::MaterialTable;
use crate::{gltf, obj, ply, raw, serialized, shapes};
use glam::{Vec2, Vec3};
use rt_core::scene::Object;
use rt_core::transform::Transform;
use rt_core::{Material, Scene};
use std::collections::HashSet;
use std::ops::Range;
use std::path::{Path, PathBuf};
use toml::Spanned;

/// The values of a geometry's `shape` key.
pub(crate) const SHAPES: [&str; 5] = ["quad", "box", "sphere", "disk", "cylinder"];

/// Most subdivisions of an icosphere (20·4^7 = 327,680 triangles).
pub(crate) const MAX_SUBDIVISIONS: u32 = 7;
/// Default icosphere subdivisions (1,280 triangles).
pub(crate) const DEFAULT_SUBDIVISIONS: u32 = 3;
/// Default disk segments.
pub(crate) const DEFAULT_SEGMENTS: u32 = 64;
/// Most disk segments.
pub(crate) const MAX_SEGMENTS: u32 = 1 << 20;

/// Triangles of one geometry as a loader or shape produces them, before placement.
#[derive(Clone, Debug, Default)]
pub(crate) struct Mesh {
    /// Vertex positions, three per triangle, in file order.
    pub tris: Vec<[Vec3; 3]>,
    /// Optional vertex normals per triangle.
    pub normals: Vec<Option<[Vec3; 3]>>,
    /// Optional vertex uvs per triangle (v = 0 at the bottom of the texture).
    pub uvs: Vec<Option<[Vec2; 3]>>,
    /// Material of each triangle: an index into `materials`.
    pub mat: Vec<Option<u32>>,
    /// Materials defined by the file, named as in the file.
    pub materials: Vec<Material>,
}

impl Mesh {
    /// Appends a triangle.
    pub fn push(
        &mut self,
        v: [Vec3; 3],
        n: Option<[Vec3; 3]>,
        uv: Option<[Vec2; 3]>,
        mat: Option<u32>,
    ) {
        self.tris.push(v);
        self.normals.push(n);
        self.uvs.push(uv);
        self.mat.push(mat);
    }

    /// Turns every triangle around: reverses its winding (so its geometric normal points the
    /// other way) and negates its vertex normals.
    pub fn flip(&mut self) {
        for i in 0..self.tris.len() {
            self.tris[i].swap(1, 2);
            if let Some(n) = &mut self.normals[i] {
                n.swap(1, 2);
                *n = n.map(|d| -d);
            }
            if let Some(uv) = &mut self.uvs[i] {
                uv.swap(1, 2);
            }
        }
    }

    /// Makes the file materials' names unique by appending `#<index>` to repeated ones.
    pub fn uniquify_material_names(&mut self) {
        let mut seen = HashSet::new();
        for (i, m) in self.materials.iter_mut().enumerate() {
            if !seen.insert(m.name.clone()) {
                m.name = format!("{}#{i}", m.name);
                seen.insert(m.name.clone());
            }
        }
    }

    /// Applies `t` to positions and normals; reverses the winding (swapping vertices 1 and 2
    /// with their attributes) if `t` mirrors, so that front faces stay front faces.
    pub fn transform(&mut self, t: &Transform) {
        let flip = t.flips_handedness();
        for i in 0..self.tris.len() {
            let v = &mut self.tris[i];
            *v = v.map(|p| t.point(p));
            if let Some(n) = &mut self.normals[i] {
                *n = n.map(|d| t.normal(d));
            }
            if flip {
                v.swap(1, 2);
                if let Some(n) = &mut self.normals[i] {
                    n.swap(1, 2);
                }
                if let Some(uv) = &mut self.uvs[i] {
                    uv.swap(1, 2);
                }
            }
        }
    }
}

/// Twice the area of a triangle, in double precision; exactly 0 for degenerate triangles.
pub(crate) fn double_area(v: &[Vec3; 3]) -> f64 {
    let [a, b, c] = v.map(|p| p.as_dvec3());
    (b - a).cross(c - a).length()
}

/// The source of a geometry's triangles.
enum Kind<'a> {
    File(&'a Spanned<String>),
    Shape(&'a str, Range<usize>),
    Inline,
}

/// Where errors about a mesh point: its file, or the geometry's table in the TOML.
enum Origin {
    File(PathBuf),
    Toml(Range<usize>),
}

impl Origin {
    fn error(&self, ctx: &Ctx, name: &str, msg: String) -> SceneError {
        match self {
            Origin::File(p) => SceneError::file(p, msg),
            Origin::Toml(span) => ctx
                .src
                .error_at(span.clone(), format!("geometry \"{name}\": {msg}")),
        }
    }
}

/// Builds every `[[geometry]]` and appends it to `scene`.
pub(crate) fn build_all(
    ctx: &mut Ctx,
    descs: &[Spanned<GeometryDesc>],
    mats: &mut MaterialTable,
    scene: &mut Scene,
) -> Result<()> {
    let mut names = HashSet::new();
    for d in descs {
        let name = &d.get_ref().name;
        if name.get_ref().is_empty() {
            return Err(ctx
                .src
                .error_at(name.span(), "geometry name must not be empty"));
        }
        if !names.insert(name.get_ref().clone()) {
            return Err(ctx.src.error_at(
                name.span(),
                format!("geometry \"{}\" is defined twice", name.get_ref()),
            ));
        }
        build(ctx, d.get_ref(), mats, scene)?;
    }
    Ok(())
}

fn build(
    ctx: &mut Ctx,
    d: &GeometryDesc,
    mats: &mut MaterialTable,
    scene: &mut Scene,
) -> Result<()> {
    let name = d.name.get_ref().as_str();
    let kind = kind(ctx, d)?;
    check_keys(ctx, d, &kind)?;
    // Look the material up before loading anything: a typo should not cost a mesh load.
    let material = match &d.material {
        Some(m) => Some(mats.lookup(m.get_ref()).ok_or_else(|| {
            ctx.src.error_at(
                m.span(),
                format!(
                    "material \"{}\" used by geometry \"{name}\" is not defined",
                    m.get_ref()
                ),
            )
        })?),
        None => None,
    };
    let transform = match &d.transform {
        Some(t) => transform(ctx, t)?,
        None => None,
    };
    let want_materials = material.is_none();
    let (mut mesh, origin) = match kind {
        Kind::File(f) => {
            let path = ctx.resolve(f.get_ref());
            let mesh = load_file(ctx, d, f, &path, want_materials)?;
            (mesh, Origin::File(path))
        }
        Kind::Shape(shape, _) => (shape_mesh(ctx, d, shape)?, Origin::Toml(d.name.span())),
        Kind::Inline => (inline_mesh(ctx, d)?, Origin::Toml(d.name.span())),
    };
    if d.smooth.as_ref().is_some_and(|b| !*b.get_ref()) {
        // Flat facets: shading normal = geometric normal, which keeps mirror and glass
        // spheres exactly energy conserving (interpolated normals cannot be).
        mesh.normals.iter_mut().for_each(|n| *n = None);
    }
    if d.flip_normals.as_ref().is_some_and(|b| *b.get_ref()) {
        mesh.flip();
    }
    if d.flip_v.as_ref().is_some_and(|b| *b.get_ref()) {
        for uv in mesh.uvs.iter_mut().flatten().flatten() {
            uv.y = 1.0 - uv.y;
        }
    }
    check_and_place(ctx, name, &origin, &mut mesh, transform.as_ref())?;

    let ids = match material {
        Some(id) => vec![id; mesh.tris.len()],
        None => file_materials(ctx, d, &mut mesh, mats)?,
    };
    let first = scene.triangles.len();
    if first + mesh.tris.len() > u32::MAX as usize {
        return Err(origin.error(
            ctx,
            name,
            "the scene has more than 2^32 - 1 triangles".into(),
        ));
    }
    scene.triangles.extend_from_slice(&mesh.tris);
    scene.normals.extend_from_slice(&mesh.normals);
    scene.uvs.extend_from_slice(&mesh.uvs);
    scene.material_ids.extend_from_slice(&ids);
    scene.objects.push(Object {
        name: name.to_string(),
        first: first as u32,
        count: mesh.tris.len() as u32,
    });
    Ok(())
}

/// Exactly one of `file`, `shape`, `positions` + `indices`.
fn kind<'a>(ctx: &Ctx, d: &'a GeometryDesc) -> Result<Kind<'a>> {
    let name = d.name.get_ref();
    let inline = d
        .positions
        .as_ref()
        .map(|p| p.span())
        .or(d.indices.as_ref().map(|i| i.span()));
    let given: Vec<(&str, Range<usize>)> = [
        ("file", d.file.as_ref().map(|f| f.span())),
        ("shape", d.shape.as_ref().map(|s| s.span())),
        ("positions", inline),
    ]
    .into_iter()
    .filter_map(|(k, s)| s.map(|s| (k, s)))
    .collect();
    match given.as_slice() {
        [] => Err(ctx.src.error_at(
            d.name.span(),
            format!(
                "geometry \"{name}\" needs one of `file`, `shape`, or `positions` and `indices`"
            ),
        )),
        [_] => Ok(if let Some(f) = &d.file {
            Kind::File(f)
        } else if let Some(s) = &d.shape {
            let shape = s.get_ref().as_str();
            if !SHAPES.contains(&shape) {
                return Err(ctx.src.error_at(
                    s.span(),
                    format!(
                        "geometry \"{name}\": unknown shape \"{shape}\"; valid shapes are quad, \
                         box, sphere, disk, cylinder"
                    ),
                ));
            }
            Kind::Shape(shape, s.span())
        } else {
            Kind::Inline
        }),
        [(a, _), (b, span), ..] => Err(ctx.src.error_at(
            span.clone(),
            format!("geometry \"{name}\" has both `{a}` and `{b}`; give exactly one source"),
        )),
    }
}

/// Rejects keys that the geometry's kind does not use, and requires the ones it needs.
fn check_keys(ctx: &Ctx, d: &GeometryDesc, kind: &Kind) -> Result<()> {
    let name = d.name.get_ref();
    let keys: [(&str, Option<Range<usize>>); 16] = [
        ("vertices", d.vertices.as_ref().map(|s| s.span())),
        ("min", d.min.as_ref().map(|s| s.span())),
        ("max", d.max.as_ref().map(|s| s.span())),
        ("center", d.center.as_ref().map(|s| s.span())),
        ("radius", d.radius.as_ref().map(|s| s.span())),
        ("subdivisions", d.subdivisions.as_ref().map(|s| s.span())),
        ("smooth", d.smooth.as_ref().map(|s| s.span())),
        ("normal", d.normal.as_ref().map(|s| s.span())),
        ("segments", d.segments.as_ref().map(|s| s.span())),
        ("p0", d.p0.as_ref().map(|s| s.span())),
        ("p1", d.p1.as_ref().map(|s| s.span())),
        ("positions", d.positions.as_ref().map(|s| s.span())),
        ("indices", d.indices.as_ref().map(|s| s.span())),
        ("normals", d.normals.as_ref().map(|s| s.span())),
        ("uvs", d.uvs.as_ref().map(|s| s.span())),
        ("flip_v", d.flip_v.as_ref().map(|s| s.span())),
    ];
    let (allowed, required, what): (&[&str], &[&str], String) = match kind {
        Kind::File(_) => (&["smooth", "flip_v"], &[], "a mesh file".into()),
        Kind::Shape("quad", _) => (
            &["vertices", "flip_v"],
            &["vertices"],
            "shape \"quad\"".into(),
        ),
        Kind::Shape("box", _) => (
            &["min", "max", "flip_v"],
            &["min", "max"],
            "shape \"box\"".into(),
        ),
        Kind::Shape("sphere", _) => (
            &["center", "radius", "subdivisions", "smooth"],
            &["radius"],
            "shape \"sphere\"".into(),
        ),
        Kind::Shape("cylinder", _) => (
            &["p0", "p1", "radius", "segments", "smooth", "flip_v"],
            &["radius"],
            "shape \"cylinder\"".into(),
        ),
        Kind::Shape(_, _) => (
            &["center", "normal", "radius", "segments", "flip_v"],
            &["radius"],
            "shape \"disk\"".into(),
        ),
        Kind::Inline => (
            &["positions", "indices", "normals", "uvs", "smooth", "flip_v"],
            &["positions", "indices"],
            "an inline mesh".into(),
        ),
    };
    for (key, span) in &keys {
        if let Some(s) = span {
            if !allowed.contains(key) {
                return Err(ctx.src.error_at(
                    s.clone(),
                    format!("geometry \"{name}\": `{key}` does not apply to {what}"),
                ));
            }
        }
    }
    for key in required {
        if keys.iter().any(|(k, s)| k == key && s.is_none()) {
            let at = match kind {
                Kind::Shape(_, s) => s.clone(),
                _ => d.name.span(),
            };
            return Err(ctx
                .src
                .error_at(at, format!("geometry \"{name}\": {what} needs `{key}`")));
        }
    }
    Ok(())
}

/// `transform = { translate, rotate, scale }`; `None` for the identity.
pub(crate) fn transform(ctx: &Ctx, t: &Spanned<TransformDesc>) -> Result<Option<Transform>> {
    let d = t.get_ref();
    if let Some(rows) = d.matrix {
        return matrix(ctx, t, rows).map(Some);
    }
    let translate = d.translate.map_or(Vec3::ZERO, Vec3::from);
    let rotate = d.rotate.map_or(Vec3::ZERO, Vec3::from);
    let scale = Vec3::from(d.scale.map_or([1.0; 3], |s| s.0));
    if !(translate.is_finite() && rotate.is_finite()) {
        return Err(ctx
            .src
            .error_at(t.span(), "transform: translate and rotate must be finite"));
    }
    if !scale.is_finite() || scale.abs().min_element() == 0.0 {
        return Err(ctx.src.error_at(
            t.span(),
            format!("transform: scale must be finite and non-zero in every component, got {scale}"),
        ));
    }
    if translate == Vec3::ZERO && rotate == Vec3::ZERO && scale == Vec3::ONE {
        return Ok(None);
    }
    Ok(Some(Transform::from_trs(translate, rotate, scale)))
}

/// `transform = { matrix = [[...], [...], [...], [0, 0, 0, 1]] }`: affine, invertible,
/// finite, and alone (not with translate, rotate or scale).
fn matrix(ctx: &Ctx, t: &Spanned<TransformDesc>, rows: [[f32; 4]; 4]) -> Result<Transform> {
    let d = t.get_ref();
    let fail = |why: &str| Err(ctx.src.error_at(t.span(), format!("transform: {why}")));
    if d.translate.is_some() || d.rotate.is_some() || d.scale.is_some() {
        return fail("matrix cannot be combined with translate, rotate or scale");
    }
    if rows.iter().flatten().any(|v| !v.is_finite()) {
        return fail("matrix entries must be finite");
    }
    if rows[3] != [0.0, 0.0, 0.0, 1.0] {
        return fail("the matrix's last row must be [0, 0, 0, 1] (affine)");
    }
    let m = glam::Mat4::from_cols_array_2d(&rows).transpose();
    let det = glam::Mat3::from_mat4(m).determinant();
    if !det.is_normal() {
        return fail("the matrix is singular");
    }
    Ok(Transform::from_mat4(m))
}

fn load_file(
    ctx: &mut Ctx,
    d: &GeometryDesc,
    f: &Spanned<String>,
    path: &Path,
    want_materials: bool,
) -> Result<Mesh> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase())
        .unwrap_or_default();
    if let Some(i) = d.shape_index.as_ref().filter(|_| ext != "serialized") {
        return Err(ctx.src.error_at(
            i.span(),
            "`shape_index` applies to Mitsuba .serialized files only",
        ));
    }
    match ext.as_str() {
        "obj" => obj::load(path, want_materials, &mut ctx.textures, &mut ctx.warnings),
        "gltf" | "glb" => gltf::load(path, want_materials, &mut ctx.textures, &mut ctx.warnings),
        "ra2" => raw::load(ctx.textures.access(), path),
        "ply" => ply::load(ctx.textures.access(), path),
        "serialized" => serialized::load(
            ctx.textures.access(),
            path,
            d.shape_index.as_ref().map_or(0, |i| *i.get_ref()),
        ),
        _ => Err(ctx.src.error_at(
            f.span(),
            format!(
                "cannot load \"{}\": unknown mesh format (use .obj, .ply, .serialized, .gltf, \
                 .glb or .ra2)",
                f.get_ref()
            ),
        )),
    }
}

fn positive(ctx: &Ctx, v: &Spanned<f32>, what: &str) -> Result<f32> {
    let x = *v.get_ref();
    if x.is_finite() && x > 0.0 {
        Ok(x)
    } else {
        Err(ctx
            .src
            .error_at(v.span(), format!("{what} must be finite and > 0, got {x}")))
    }
}

fn shape_mesh(ctx: &Ctx, d: &GeometryDesc, shape: &str) -> Result<Mesh> {
    let name = d.name.get_ref();
    let center = match &d.center {
        Some(c) => finite3(ctx, c, "center")?,
        None => Vec3::ZERO,
    };
    Ok(match shape {
        "quad" => {
            let v = d.vertices.as_ref().expect("checked");
            if v.get_ref().len() != 4 {
                return Err(ctx.src.error_at(
                    v.span(),
                    format!(
                        "geometry \"{name}\": a quad needs 4 vertices, got {}",
                        v.get_ref().len()
                    ),
                ));
            }
            let p: Vec<Vec3> = v.get_ref().iter().map(|&p| Vec3::from(p)).collect();
            if !p.iter().all(|p| p.is_finite()) {
                return Err(ctx.src.error_at(
                    v.span(),
                    format!("geometry \"{name}\": vertices must be finite"),
                ));
            }
            shapes::quad([p[0], p[1], p[2], p[3]])
        }
        "box" => {
            let min = finite3(ctx, d.min.as_ref().expect("checked"), "min")?;
            let max_s = d.max.as_ref().expect("checked");
            let max = finite3(ctx, max_s, "max")?;
            if !max.cmpgt(min).all() {
                return Err(ctx.src.error_at(
                    max_s.span(),
                    format!(
                        "geometry \"{name}\": box `max` {max} must be greater than `min` {min} \
                         in x, y and z"
                    ),
                ));
            }
            shapes::cuboid(min, max)
        }
        "sphere" => {
            let r = positive(ctx, d.radius.as_ref().expect("checked"), "radius")?;
            let mut s = DEFAULT_SUBDIVISIONS;
            if let Some(sub) = &d.subdivisions {
                s = *sub.get_ref();
                if s > MAX_SUBDIVISIONS {
                    return Err(ctx.src.error_at(
                        sub.span(),
                        format!("subdivisions must be at most {MAX_SUBDIVISIONS}, got {s}"),
                    ));
                }
            }
            shapes::sphere(center, r, s)
        }
        "cylinder" => {
            let r = positive(ctx, d.radius.as_ref().expect("checked"), "radius")?;
            let p0 =
                d.p0.as_ref()
                    .map_or(Ok(Vec3::ZERO), |p| finite3(ctx, p, "p0"))?;
            let p1 =
                d.p1.as_ref()
                    .map_or(Ok(Vec3::Z), |p| finite3(ctx, p, "p1"))?;
            if p0 == p1 {
                let at =
                    d.p1.as_ref()
                        .or(d.p0.as_ref())
                        .map_or(d.name.span(), |p| p.span());
                return Err(ctx.src.error_at(
                    at,
                    format!("geometry \"{name}\": cylinder `p0` and `p1` must differ"),
                ));
            }
            shapes::cylinder(p0, p1, r, segments(ctx, d)?)
        }
        _ => {
            let r = positive(ctx, d.radius.as_ref().expect("checked"), "radius")?;
            let mut n = Vec3::Y;
            if let Some(ns) = &d.normal {
                n = finite3(ctx, ns, "normal")?;
                if n.length_squared() == 0.0 {
                    return Err(ctx.src.error_at(ns.span(), "normal must not be zero"));
                }
                n = n.normalize();
            }
            shapes::disk(center, n, r, segments(ctx, d)?)
        }
    })
}

/// A disk's or cylinder's `segments`.
fn segments(ctx: &Ctx, d: &GeometryDesc) -> Result<u32> {
    let Some(s) = &d.segments else {
        return Ok(DEFAULT_SEGMENTS);
    };
    let n = *s.get_ref();
    if !(3..=MAX_SEGMENTS).contains(&n) {
        return Err(ctx.src.error_at(
            s.span(),
            format!("segments must be in [3, {MAX_SEGMENTS}], got {n}"),
        ));
    }
    Ok(n)
}

/// `positions` + `indices` (+ optional per-vertex `normals` and `uvs`).
fn inline_mesh(ctx: &Ctx, d: &GeometryDesc) -> Result<Mesh> {
    let name = d.name.get_ref();
    let pos = d.positions.as_ref().expect("checked");
    let idx = d.indices.as_ref().expect("checked");
    let p = pos.get_ref();
    if let Some(i) = p.iter().position(|v| !v.iter().all(|x| x.is_finite())) {
        return Err(ctx.src.error_at(
            pos.span(),
            format!(
                "geometry \"{name}\": position {i} is not finite: {:?}",
                p[i].0
            ),
        ));
    }
    let per_vertex = |len: usize, key: &str, span: Range<usize>| {
        if len == p.len() {
            Ok(())
        } else {
            Err(ctx.src.error_at(
                span,
                format!(
                    "geometry \"{name}\": `{key}` has {len} entries but there are {} positions",
                    p.len()
                ),
            ))
        }
    };
    if let Some(n) = &d.normals {
        per_vertex(n.get_ref().len(), "normals", n.span())?;
    }
    if let Some(u) = &d.uvs {
        per_vertex(u.get_ref().len(), "uvs", u.span())?;
    }
    let mut m = Mesh::default();
    for (t, tri) in idx.get_ref().iter().enumerate() {
        let tri = tri.0;
        if let Some(&bad) = tri.iter().find(|&&i| i as usize >= p.len()) {
            return Err(ctx.src.error_at(
                idx.span(),
                format!(
                    "geometry \"{name}\": indices[{t}] = {tri:?} references position {bad} but \
                     there are {} positions",
                    p.len()
                ),
            ));
        }
        let at = |a: &[V3]| tri.map(|i| Vec3::from(a[i as usize]));
        m.push(
            at(p),
            d.normals.as_ref().map(|n| at(n.get_ref())),
            d.uvs
                .as_ref()
                .map(|u| tri.map(|i| Vec2::from(u.get_ref()[i as usize]))),
            None,
        );
    }
    Ok(m)
}

/// Places the mesh and checks it: non-empty, finite, not entirely degenerate. Drops invalid
/// normals and uvs per triangle, and counts zero-area triangles, with warnings.
fn check_and_place(
    ctx: &mut Ctx,
    name: &str,
    origin: &Origin,
    m: &mut Mesh,
    t: Option<&Transform>,
) -> Result<()> {
    let n = m.tris.len();
    if n == 0 {
        return Err(origin.error(ctx, name, "the mesh has no triangles".into()));
    }
    let not_finite = |m: &Mesh| m.tris.iter().position(|v| !v.iter().all(|p| p.is_finite()));
    if let Some(i) = not_finite(m) {
        return Err(origin.error(
            ctx,
            name,
            format!(
                "triangle {i} has a non-finite vertex coordinate: {:?}",
                m.tris[i]
            ),
        ));
    }
    if let Some(t) = t {
        m.transform(t);
        if let Some(i) = not_finite(m) {
            return Err(origin.error(
                ctx,
                name,
                format!("triangle {i} is not finite after the transform (overflow)"),
            ));
        }
    }
    let mut bad_normals = 0;
    for nrm in &mut m.normals {
        if let Some(v) = nrm {
            // Unit length for the shading code; a zero or non-finite normal is dropped.
            let unit = v.map(|d| d.normalize_or_zero());
            if unit
                .iter()
                .all(|d| d.is_finite() && d.length_squared() > 0.5)
            {
                *v = unit;
            } else {
                *nrm = None;
                bad_normals += 1;
            }
        }
    }
    let mut bad_uvs = 0;
    for uv in &mut m.uvs {
        if uv.is_some_and(|u| !u.iter().all(|x| x.is_finite())) {
            *uv = None;
            bad_uvs += 1;
        }
    }
    let zero = m.tris.iter().filter(|v| double_area(v) == 0.0).count();
    // A mesh file of nothing but zero-area triangles is invisible, not broken: Mitsuba loads
    // one (the staircase has some), so it gets the warning below; a shape or inline mesh that
    // is all degenerate is a mistake in the scene itself.
    if zero == n && matches!(origin, Origin::Toml(_)) {
        return Err(origin.error(
            ctx,
            name,
            format!("all {n} triangles have zero area (degenerate mesh)"),
        ));
    }
    let mut warn = |what: String| ctx.warnings.push(format!("geometry \"{name}\": {what}"));
    if zero > 0 {
        warn(format!(
            "{zero} of {n} triangles have zero area (kept; they are never hit)"
        ));
    }
    if bad_normals > 0 {
        warn(format!(
            "dropped zero or non-finite vertex normals of {bad_normals} triangles"
        ));
    }
    if bad_uvs > 0 {
        warn(format!("dropped non-finite uvs of {bad_uvs} triangles"));
    }
    Ok(())
}

/// Adds the file's materials that the triangles use to the table as "<geometry>/<material>"
/// and returns the triangles' material indices.
fn file_materials(
    ctx: &Ctx,
    d: &GeometryDesc,
    mesh: &mut Mesh,
    mats: &mut MaterialTable,
) -> Result<Vec<u32>> {
    let name = d.name.get_ref();
    mesh.uniquify_material_names();
    let missing = mesh.mat.iter().filter(|m| m.is_none()).count();
    if missing > 0 {
        let why = if mesh.materials.is_empty() {
            "it has no `material` and its source defines none".to_string()
        } else {
            format!(
                "{missing} of its {} triangles have no material in the file",
                mesh.tris.len()
            )
        };
        return Err(ctx.src.error_at(
            d.name.span(),
            format!("geometry \"{name}\" has no material: {why}; set `material = \"...\"`"),
        ));
    }
    let mut ids: Vec<Option<u32>> = vec![None; mesh.materials.len()];
    let mut out = Vec::with_capacity(mesh.tris.len());
    for m in &mesh.mat {
        let k = m.expect("checked") as usize;
        let id = match ids[k] {
            Some(id) => id,
            None => {
                let mut mat = mesh.materials[k].clone();
                mat.name = format!("{name}/{}", mat.name);
                let full = mat.name.clone();
                let id = mats.insert(mat).ok_or_else(|| {
                    ctx.src.error_at(
                        d.name.span(),
                        format!("geometry \"{name}\": material name \"{full}\" is already taken"),
                    )
                })?;
                mats.lookup(&full);
                ids[k] = Some(id);
                id
            }
        };
        out.push(id);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use crate::load::tests::{err, line_of, load_in, ok};
    use glam::{Vec2, Vec3};
    use rt_core::Rgb;

    /// The triangles of the geometry named `name`.
    fn tris(s: &crate::LoadedScene, name: &str) -> Vec<[Vec3; 3]> {
        let o = s.scene.objects.iter().find(|o| o.name == name).unwrap();
        s.scene.triangles[o.first as usize..(o.first + o.count) as usize].to_vec()
    }

    fn geom(body: &str) -> String {
        format!("[[geometry]]\nname = \"g\"\nmaterial = \"light\"\n{body}\n")
    }

    fn nrm(t: &[Vec3; 3]) -> Vec3 {
        (t[1] - t[0]).cross(t[2] - t[0]).normalize()
    }

    #[test]
    fn quad_vertices_are_split_as_documented() {
        let s = ok(&geom(
            "shape = \"quad\"\nvertices = [[0, 0, 0], [2, 0, 0], [2, 0, -3], [0, 0, -3]]",
        ));
        let v = [
            Vec3::ZERO,
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(2.0, 0.0, -3.0),
            Vec3::new(0.0, 0.0, -3.0),
        ];
        assert_eq!(tris(&s, "g"), vec![[v[0], v[1], v[2]], [v[0], v[2], v[3]]]);
        assert_eq!(
            s.scene.objects[1].first, 2,
            "appended after the lamp, in file order"
        );
        let e = err(&geom(
            "shape = \"quad\"\nvertices = [[0, 0, 0], [2, 0, 0], [2, 0, -3]]",
        ));
        assert!(
            e.contains("geometry \"g\": a quad needs 4 vertices, got 3"),
            "{e}"
        );
        let e = err(&geom(
            "shape = \"quad\"\nvertices = [[0, 0, 0], [2, 0, 0], [2, nan, -3], [0, 0, 1]]",
        ));
        assert!(e.contains("vertices must be finite"), "{e}");
        let e = err(&geom("shape = \"quad\""));
        assert!(
            e.contains("geometry \"g\": shape \"quad\" needs `vertices`"),
            "{e}"
        );
        let e = err(&geom(
            "shape = \"quad\"\nvertices = [[0, 0, 0], [0, 0, 0], [0, 0, 0], [0, 0, 0]]",
        ));
        assert!(
            e.contains("geometry \"g\": all 2 triangles have zero area"),
            "{e}"
        );
    }

    #[test]
    fn box_min_max() {
        let s = ok(&geom("shape = \"box\"\nmin = [-1, 0, -1]\nmax = [1, 2, 1]"));
        let t = tris(&s, "g");
        assert_eq!(t.len(), 12);
        for t in &t {
            let c = (t[0] + t[1] + t[2]) / 3.0 - Vec3::new(0.0, 1.0, 0.0);
            assert!(nrm(t).dot(c) > 0.0);
        }
        let e = err(&geom("shape = \"box\"\nmin = [0, 0, 0]\nmax = [1, 0, 1]"));
        assert!(
            e.contains("box `max` [1, 0, 1] must be greater than `min` [0, 0, 0]"),
            "{e}"
        );
        let e = err(&geom("shape = \"box\"\nmin = [0, 0, 0]"));
        assert!(e.contains("shape \"box\" needs `max`"), "{e}");
    }

    #[test]
    fn sphere_center_radius_subdivisions() {
        let s = ok(&geom(
            "shape = \"sphere\"\ncenter = [1, 2, 3]\nradius = 0.5",
        ));
        let t = tris(&s, "g");
        assert_eq!(t.len(), 1280, "default subdivisions 3");
        for p in t.iter().flatten() {
            assert!(((*p - Vec3::new(1.0, 2.0, 3.0)).length() - 0.5).abs() < 1e-5);
        }
        assert!(s.scene.normals[2].is_some(), "smooth normals");
        let flat = ok(&geom("shape = \"sphere\"\nradius = 1\nsmooth = false"));
        assert!(
            flat.scene.normals.iter().all(Option::is_none),
            "smooth = false drops normals"
        );
        let s = ok(&geom("shape = \"sphere\"\nradius = 2\nsubdivisions = 0"));
        assert_eq!(tris(&s, "g").len(), 20);
        assert!(
            (tris(&s, "g")[0][0].length() - 2.0).abs() < 1e-5,
            "default centre is the origin"
        );
        for (body, want) in [
            ("radius = 0", "radius must be finite and > 0, got 0"),
            ("radius = -1", "radius must be finite and > 0"),
            ("radius = nan", "radius must be finite and > 0"),
            (
                "radius = 1\nsubdivisions = 8",
                "subdivisions must be at most 7",
            ),
            ("center = [0, 0, 0]", "shape \"sphere\" needs `radius`"),
            ("radius = 1\ncenter = [inf, 0, 0]", "center must be finite"),
        ] {
            let e = err(&geom(&format!("shape = \"sphere\"\n{body}")));
            assert!(e.contains(want), "{body}: {e}");
        }
    }

    #[test]
    fn disk_center_normal_radius_segments() {
        let s = ok(&geom(
            "shape = \"disk\"\ncenter = [0, 1, 0]\nnormal = [0, 0, 2]\nradius = 3\nsegments = 8",
        ));
        let t = tris(&s, "g");
        assert_eq!(t.len(), 8);
        for t in &t {
            assert!((nrm(t) - Vec3::Z).length() < 1e-5);
            assert_eq!(t[0], Vec3::new(0.0, 1.0, 0.0));
            assert!(((t[1] - t[0]).length() - 3.0).abs() < 1e-5);
        }
        let s = ok(&geom("shape = \"disk\"\nradius = 1"));
        let t = tris(&s, "g");
        assert_eq!(t.len(), 64, "default segments");
        assert!(
            t.iter().all(|t| (nrm(t) - Vec3::Y).length() < 1e-5),
            "default normal +y"
        );
        for (body, want) in [
            ("radius = 1\nnormal = [0, 0, 0]", "normal must not be zero"),
            ("radius = 1\nsegments = 2", "segments must be in [3, "),
            ("radius = 0", "radius must be finite and > 0"),
        ] {
            let e = err(&geom(&format!("shape = \"disk\"\n{body}")));
            assert!(e.contains(want), "{body}: {e}");
        }
    }

    #[test]
    fn inline_mesh_positions_indices_normals_uvs() {
        let s = ok(&geom(
            "positions = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]]\nindices = [[0, 1, 2], [2, 1, 3]]\n\
             normals = [[0, 0, 2], [0, 0, 1], [0, 0, 1], [0, 0, 1]]\nuvs = [[0, 0], [1, 0], [0, 1], [1, 1]]",
        ));
        let t = tris(&s, "g");
        assert_eq!(t[1], [Vec3::Y, Vec3::X, Vec3::new(1.0, 1.0, 0.0)]);
        assert_eq!(
            s.scene.normals[2],
            Some([Vec3::Z; 3]),
            "normals are normalised"
        );
        assert_eq!(s.scene.uvs[3], Some([Vec2::Y, Vec2::X, Vec2::ONE]));
        let flipped = ok(&geom(
            "positions = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]]\nindices = [[0, 1, 2], [2, 1, 3]]\n\
             uvs = [[0, 0], [1, 0], [0, 1], [1, 1]]\nflip_v = true",
        ));
        assert_eq!(flipped.scene.uvs[3], Some([Vec2::ZERO, Vec2::ONE, Vec2::X]));
        for (body, want) in [
            ("positions = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]\nindices = [[0, 1, 3]]", "indices[0] = [0, 1, 3] references position 3 but there are 3 positions"),
            ("positions = [[0, 0, 0], [1, 0, 0], [0, nan, 0]]\nindices = [[0, 1, 2]]", "position 2 is not finite"),
            ("positions = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]\nindices = []", "geometry \"g\": the mesh has no triangles"),
            ("positions = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]", "an inline mesh needs `indices`"),
            ("indices = [[0, 1, 2]]", "an inline mesh needs `positions`"),
            ("positions = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]\nindices = [[0, 1, 2]]\nnormals = [[0, 0, 1]]", "`normals` has 1 entries but there are 3 positions"),
            ("positions = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]\nindices = [[0, 1, 2]]\nuvs = [[0, 0]]", "`uvs` has 1 entries but there are 3 positions"),
            ("positions = [[0, 0, 0], [1, 0, 0], [2, 0, 0]]\nindices = [[0, 1, 2], [0, 0, 1]]", "all 2 triangles have zero area"),
            ("positions = [[0, 0, 0], [1, 0, 0], [2, 0, 0]]\nindices = [[0, 1, -2]]", "-2"),
        ] {
            let e = err(&geom(body));
            assert!(e.contains(want), "{body}: {e}");
        }
        // Zero-area triangles among good ones are kept, with a warning.
        let s = ok(&geom("positions = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]\nindices = [[0, 1, 2], [0, 0, 1], [1, 1, 1]]"));
        assert_eq!(tris(&s, "g").len(), 3);
        assert!(
            s.warnings.iter().any(|w| w
                == "geometry \"g\": 2 of 3 triangles have zero area (kept; they are never hit)"),
            "{:?}",
            s.warnings
        );
        let s = ok(&geom("positions = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]\nindices = [[0, 1, 2]]\nnormals = [[0, 0, 0], [0, 0, 1], [0, 0, 1]]"));
        assert_eq!(s.scene.normals_of(2), None);
        assert!(
            s.warnings
                .iter()
                .any(|w| w.contains("dropped zero or non-finite vertex normals of 1 triangles")),
            "{:?}",
            s.warnings
        );
    }

    #[test]
    fn transform_translate_rotate_scale() {
        let quad = "shape = \"quad\"\nvertices = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]\n";
        let s = ok(&geom(&format!(
            "{quad}transform = {{ translate = [1, 2, 3] }}"
        )));
        assert_eq!(tris(&s, "g")[0][1], Vec3::new(2.0, 2.0, 3.0));
        let s = ok(&geom(&format!("{quad}transform = {{ scale = 2 }}")));
        assert_eq!(tris(&s, "g")[0][2], Vec3::new(2.0, 2.0, 0.0));
        let s = ok(&geom(&format!("{quad}transform = {{ scale = [1, 3, 1] }}")));
        assert_eq!(tris(&s, "g")[0][2], Vec3::new(1.0, 3.0, 0.0));
        // rotate: degrees about x, then y, then z. +y about x by 90° is +z, then about y by 90° is +x.
        let s = ok(&geom(&format!(
            "{quad}transform = {{ rotate = [90, 90, 0] }}"
        )));
        let p = tris(&s, "g")[1][2];
        assert!((p - Vec3::X).length() < 1e-5, "{p}");
        // Order: scale, rotate, translate.
        let s = ok(&geom(&format!(
            "{quad}transform = {{ translate = [0, 0, 5], rotate = [0, 0, 90], scale = 2 }}"
        )));
        let p = tris(&s, "g")[0][1];
        assert!((p - Vec3::new(0.0, 2.0, 5.0)).length() < 1e-5, "{p}");
        for bad in [
            "scale = 0",
            "scale = [1, 0, 1]",
            "scale = nan",
            "translate = [inf, 0, 0]",
            "rotate = [0, nan, 0]",
        ] {
            let e = err(&geom(&format!("{quad}transform = {{ {bad} }}")));
            assert!(e.contains("transform:"), "{bad}: {e}");
        }
        let e = err(&geom(&format!("{quad}transform = {{ shear = 1 }}")));
        assert!(e.contains("unknown field `shear`"), "{e}");
    }

    #[test]
    fn mirroring_transforms_keep_front_faces_in_front_and_transform_normals() {
        let mesh = "positions = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]\nindices = [[0, 1, 2]]\n\
                    normals = [[1, 0, 1], [1, 0, 1], [1, 0, 1]]\nuvs = [[0, 0], [1, 0], [0, 1]]\n";
        let s = ok(&geom(&format!(
            "{mesh}transform = {{ scale = [-1, 1, 1] }}"
        )));
        let t = tris(&s, "g")[0];
        // The front normal was +z; mirrored in x it must still be +z.
        assert!((nrm(&t) - Vec3::Z).length() < 1e-6, "{t:?}");
        assert_eq!(
            t,
            [Vec3::ZERO, Vec3::Y, -Vec3::X],
            "vertices 1 and 2 swapped"
        );
        assert_eq!(s.scene.uvs[2], Some([Vec2::ZERO, Vec2::Y, Vec2::X]));
        let n = s.scene.normals[2].unwrap()[0];
        assert!(
            (n - Vec3::new(-1.0, 0.0, 1.0).normalize()).length() < 1e-6,
            "{n}"
        );
        // Non-uniform scale: normals use the inverse transpose.
        let s = ok(&geom(&format!("{mesh}transform = {{ scale = [2, 1, 1] }}")));
        let n = s.scene.normals[2].unwrap()[0];
        assert!(
            (n - Vec3::new(0.5, 0.0, 1.0).normalize()).length() < 1e-6,
            "{n}"
        );
    }

    #[test]
    fn sources_and_keys_are_checked() {
        for (body, want) in [
            (
                "",
                "geometry \"g\" needs one of `file`, `shape`, or `positions` and `indices`",
            ),
            (
                "shape = \"quad\"\nfile = \"a.obj\"",
                "geometry \"g\" has both `file` and `shape`",
            ),
            (
                "shape = \"cone\"",
                "unknown shape \"cone\"; valid shapes are quad, box, sphere, disk, cylinder",
            ),
            (
                "shape = \"box\"\nmin = [0, 0, 0]\nmax = [1, 1, 1]\nradius = 1",
                "geometry \"g\": `radius` does not apply to shape \"box\"",
            ),
            (
                "file = \"a.obj\"\nsubdivisions = 2",
                "`subdivisions` does not apply to a mesh file",
            ),
            (
                "shape = \"sphere\"\nradius = 1\npositions = [[0, 0, 0]]",
                "has both `shape` and `positions`",
            ),
            (
                "file = \"a.stl\"",
                "cannot load \"a.stl\": unknown mesh format (use .obj, .ply, .serialized, .gltf",
            ),
            (
                "file = \"a.obj\"\nshape_index = 1",
                "`shape_index` applies to Mitsuba .serialized files only",
            ),
            (
                "shape = \"cylinder\"\nradius = 1\np0 = [0, 1, 0]\np1 = [0, 1, 0]",
                "cylinder `p0` and `p1` must differ",
            ),
            (
                "shape = \"disk\"\nradius = 1\nsmooth = false",
                "`smooth` does not apply to shape \"disk\"",
            ),
            ("file = \"missing.obj\"", "missing.obj: cannot open"),
            ("file = \"missing.glb\"", "missing.glb: cannot open"),
            ("file = \"missing.ra2\"", "missing.ra2: cannot open"),
        ] {
            let e = load_in(std::path::Path::new("."), &geom(body)).unwrap_err();
            assert!(e.contains(want), "{body}: {e}");
        }
        let extra = geom(
            "shape = \"quad\"\nvertices = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]\nradius = 2",
        );
        let e = err(&extra);
        assert!(
            e.starts_with(&format!("t.toml:{}:10:", line_of(&extra, "radius = 2"))),
            "{e}"
        );
    }

    #[test]
    fn materials_of_geometry() {
        let quad = "shape = \"quad\"\nvertices = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]";
        let extra = format!("[[geometry]]\nname = \"box\"\nmaterial = \"red\"\n{quad}\n");
        let e = err(&extra);
        assert_eq!(
            e,
            format!(
                "t.toml:{}:12: material \"red\" used by geometry \"box\" is not defined",
                line_of(&extra, "material = \"red\"")
            )
        );
        let e = err(&format!("[[geometry]]\nname = \"box\"\n{quad}\n"));
        assert!(e.contains("geometry \"box\" has no material: it has no `material` and its source defines none"), "{e}");
        let e = err(&format!(
            "[[geometry]]\nname = \"lamp\"\nmaterial = \"light\"\n{quad}\n"
        ));
        assert!(e.contains("geometry \"lamp\" is defined twice"), "{e}");
        let s = ok(&format!("[[material]]\nname = \"red\"\ncolor = [1, 0, 0]\n[[geometry]]\nname = \"q\"\nmaterial = \"red\"\n{quad}\n"));
        assert_eq!(s.scene.material_ids[2..], [1, 1]);
        assert_eq!(
            s.scene.materials[1].layers[0].color,
            Rgb::new(1.0, 0.0, 0.0)
        );
    }

    #[test]
    fn file_materials_are_named_after_the_geometry() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(
            dir.path().join("a.mtl"),
            "newmtl red\nKd 1 0 0\nnewmtl lamp\nKe 2 2 2\n",
        )
        .unwrap();
        std::fs::write(
            dir.path().join("a.obj"),
            "mtllib a.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\nusemtl lamp\nf 1 3 2\n",
        )
        .unwrap();
        let s = load_in(dir.path(), "[[geometry]]\nname = \"a\"\nfile = \"a.obj\"\n").unwrap();
        let names: Vec<&str> = s.scene.materials.iter().map(|m| m.name.as_str()).collect();
        assert_eq!(names, ["light", "a/red", "a/lamp"]);
        assert_eq!(s.scene.material_ids[2..], [1, 2]);
        assert_eq!(s.scene.lights().emitter_count(), 3);
        // [[assign]] can use them, and `material` overrides them.
        let s = load_in(
            dir.path(),
            "[[geometry]]\nname = \"a\"\nfile = \"a.obj\"\n[[assign]]\ngeometry = \"a\"\ntriangles = [1, 2]\nmaterial = \"a/red\"\n",
        )
        .unwrap();
        assert_eq!(s.scene.material_ids[2..], [1, 1]);
        let s = load_in(
            dir.path(),
            "[[geometry]]\nname = \"a\"\nfile = \"a.obj\"\nmaterial = \"light\"\n",
        )
        .unwrap();
        assert_eq!(s.scene.materials.len(), 1);
        assert_eq!(s.scene.material_ids[2..], [0, 0]);
        // Faces before any usemtl have no material.
        std::fs::write(
            dir.path().join("b.obj"),
            "mtllib a.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nusemtl red\nf 1 2 3\n",
        )
        .unwrap();
        let e = load_in(dir.path(), "[[geometry]]\nname = \"b\"\nfile = \"b.obj\"\n").unwrap_err();
        assert!(
            e.contains(
                "geometry \"b\" has no material: 1 of its 2 triangles have no material in the file"
            ),
            "{e}"
        );
    }
}
