//! The scene element tree as a TOML document of our format: sensor → `[[camera]]` and
//! `[render]`, shapes → `[[geometry]]`, BSDFs → `[[material]]`, environment emitters →
//! `[environment]`, point, spot and directional emitters → `[[light]]`, the integrator →
//! `[render]`.

use std::collections::{HashMap, HashSet};

use glam::{DMat4, DVec3, DVec4};
use toml::{Table, Value};

use super::bsdf;
use super::props::{Color, Props};
use super::spectrum::Role;
use super::xml::Node;
use crate::error::SceneError;

/// Unlimited depth: the integrators' largest bounce limit (roulette ends paths long before).
const UNLIMITED_DEPTH: i64 = 10_000;
/// Subdivisions of the icosphere standing in for an analytic sphere (20·4⁵ triangles).
const SPHERE_SUBDIVISIONS: i64 = 5;
/// Quads around the tube standing in for an analytic cylinder.
const CYLINDER_SEGMENTS: i64 = 512;

/// Builds the TOML table of the scene rooted at `root`. `file_name` maps a file name as
/// written in the scene to the string the TOML should hold.
pub(super) fn build(
    root: &Node,
    file_name: &dyn Fn(&str) -> String,
    warnings: &mut Vec<String>,
) -> Result<Table, SceneError> {
    let mut ids = HashMap::new();
    collect_ids(root, &mut ids)?;
    let mut b = Builder {
        ids,
        file_name,
        materials: Vec::new(),
        by_node: HashMap::new(),
        used: HashSet::new(),
        geometry: Vec::new(),
        groups: HashMap::new(),
        instances: Vec::new(),
        placed: 0,
        cameras: Vec::new(),
        environment: None,
        lights: Vec::new(),
        render: Table::new(),
        warnings,
    };
    // A scene's own children are all objects (`<default>`s were consumed by the reader).
    for c in &root.children {
        match c.tag.as_str() {
            "integrator" => b.integrator(c)?,
            "sensor" => b.sensor(c)?,
            "shape" => b.shape(c)?,
            "emitter" => b.environment(c)?,
            // Declarations: converted where a shape refers to them.
            "bsdf" | "texture" if c.attr("id").is_some() => {}
            "bsdf" => bsdf::unused(c, &|r| resolve(&b.ids, r), b.warnings)?,
            other => {
                return Err(c.at.error(format!(
                    "<{other}{}> is not supported at the top of a scene",
                    c.attr("type")
                        .map(|t| format!(" type=\"{t}\""))
                        .unwrap_or_default()
                )))
            }
        }
    }
    if b.cameras.is_empty() {
        return Err(root.at.error("the scene has no <sensor>"));
    }
    let mut doc = Table::new();
    if let Some(env) = b.environment.take() {
        doc.insert("environment".into(), Value::Table(env));
    }
    let arrays = [
        ("camera", std::mem::take(&mut b.cameras)),
        ("material", std::mem::take(&mut b.materials)),
        ("geometry", std::mem::take(&mut b.geometry)),
        ("instance", std::mem::take(&mut b.instances)),
        ("light", std::mem::take(&mut b.lights)),
    ];
    for (key, tables) in arrays {
        if !tables.is_empty() {
            doc.insert(
                key.into(),
                Value::Array(tables.into_iter().map(Value::Table).collect()),
            );
        }
    }
    if !b.render.is_empty() {
        doc.insert("render".into(), Value::Table(std::mem::take(&mut b.render)));
    }
    Ok(doc)
}

fn collect_ids<'a>(n: &'a Node, ids: &mut HashMap<String, &'a Node>) -> Result<(), SceneError> {
    for c in &n.children {
        if c.tag != "ref" {
            if let Some(id) = c.attr("id") {
                if ids.insert(id.to_string(), c).is_some() {
                    return Err(c.at.error(format!("id \"{id}\" is defined twice")));
                }
            }
        }
        collect_ids(c, ids)?;
    }
    Ok(())
}

struct Builder<'a, 'w> {
    ids: HashMap<String, &'a Node>,
    file_name: &'w dyn Fn(&str) -> String,
    materials: Vec<Table>,
    /// Name and table of each converted BSDF element, by address.
    by_node: HashMap<*const Node, (String, Table)>,
    /// Names of the materials in `materials`.
    used: HashSet<String>,
    geometry: Vec<Table>,
    /// The geometry names of each shape group that an instance placed, by address: a group
    /// is converted when first placed (one that nothing places is not rendered, as in
    /// Mitsuba).
    groups: HashMap<*const Node, Vec<String>>,
    instances: Vec<Table>,
    /// `instance` elements seen (each gives one `[[instance]]` per group member).
    placed: usize,
    cameras: Vec<Table>,
    environment: Option<Table>,
    /// `[[light]]` tables of the point, spot and directional emitters.
    lights: Vec<Table>,
    render: Table,
    warnings: &'w mut Vec<String>,
}

/// `transform = { matrix = [...] }` of an affine `m`.
fn matrix_table(m: &DMat4) -> Value {
    let rows: Vec<Value> = (0..4)
        .map(|r| {
            Value::Array(
                m.row(r)
                    .to_array()
                    .iter()
                    .map(|&x| Value::Float(x))
                    .collect(),
            )
        })
        .collect();
    let mut t = Table::new();
    t.insert("matrix".into(), Value::Array(rows));
    Value::Table(t)
}

fn arr(v: DVec3) -> Value {
    Value::Array(v.to_array().iter().map(|&x| Value::Float(x)).collect())
}

/// The element a `<ref id>` names.
/// True if BSDF `b` reads a texture, nested or by reference, in it or in its nested BSDFs.
fn reads_texture(ids: &HashMap<String, &Node>, b: &Node) -> bool {
    b.children.iter().any(|c| {
        let t = if c.tag == "ref" {
            match resolve(ids, c) {
                Ok(t) => t,
                Err(_) => return false,
            }
        } else {
            c
        };
        t.tag == "texture" || (t.tag == "bsdf" && reads_texture(ids, t))
    })
}

fn resolve<'a>(ids: &HashMap<String, &'a Node>, r: &Node) -> Result<&'a Node, SceneError> {
    let id = r.attr("id").ok_or_else(|| r.at.error("<ref> has no id"))?;
    ids.get(id).copied().ok_or_else(|| {
        r.at.error(format!("<ref id=\"{id}\">: no element has this id"))
    })
}

impl<'a> Builder<'a, '_> {
    fn integrator(&mut self, n: &Node) -> Result<(), SceneError> {
        let p = Props::new(n);
        match n.plugin()? {
            "path" => {
                let depth = p.integer("max_depth")?.unwrap_or(-1);
                let ours = match depth {
                    -1 => UNLIMITED_DEPTH,
                    d if d >= 1 => (d - 1).min(UNLIMITED_DEPTH),
                    d => return Err(p.error(format!("max_depth {d}: must be -1 or at least 1"))),
                };
                self.render.insert("max_depth".into(), ours.into());
                p.ignore(
                    "rr_depth",
                    "Russian roulette starts where ours does (the expectation is the same)",
                );
                if p.boolean("hide_emitters")? == Some(true) {
                    return Err(p.error("hide_emitters = true is not supported"));
                }
            }
            "direct" => {
                self.render.insert("integrator".into(), "direct".into());
                p.ignore(
                    "emitter_samples",
                    "one light sample per hit (the same expectation)",
                );
                p.ignore(
                    "bsdf_samples",
                    "one BSDF sample per hit (the same expectation)",
                );
                if p.boolean("hide_emitters")? == Some(true) {
                    return Err(p.error("hide_emitters = true is not supported"));
                }
            }
            other => {
                return Err(n.at.error(format!(
                    "integrator \"{other}\" is not supported (path and direct are)"
                )))
            }
        }
        p.finish(self.warnings)
    }

    fn sensor(&mut self, n: &Node) -> Result<(), SceneError> {
        let p = Props::new(n);
        let ty = n.plugin()?;
        if ty != "perspective" && ty != "thinlens" {
            return Err(n.at.error(format!(
                "sensor \"{ty}\" is not supported (perspective and thinlens are)"
            )));
        }
        let mut cam = Table::new();
        let name = n
            .attr("id")
            .map_or_else(|| format!("sensor{}", self.cameras.len()), str::to_string);
        cam.insert("name".into(), name.into());
        let m = p.transform("to_world")?.unwrap_or(DMat4::IDENTITY);
        let (pos, dir, up) = camera_frame(&p, &m)?;
        cam.insert("position".into(), arr(pos));
        cam.insert("look_at".into(), arr(pos + dir));
        cam.insert("up".into(), arr(up));

        // The film first: the field of view's axis depends on its size.
        let films = p.objects("film");
        let (w, h) = match films.as_slice() {
            [] => (768, 576),
            [f] => self.film(f, &mut cam)?,
            _ => return Err(p.error("has more than one <film>")),
        };
        cam.insert(
            "resolution".into(),
            Value::Array(vec![Value::Integer(w), Value::Integer(h)]),
        );
        let fov = match (p.float("fov")?, p.string("focal_length")?) {
            (Some(f), None) => f,
            (None, Some(fl)) => focal_length_fov(&p, fl)?,
            // Mitsuba's default lens.
            (None, None) => focal_length_fov(&p, "50mm")?,
            (Some(_), Some(_)) => return Err(p.error("has both fov and focal_length")),
        };
        let axis = p.string("fov_axis")?.unwrap_or("x");
        cam.insert(
            "fov".into(),
            vertical_fov(&p, fov, axis, w as f64, h as f64)?.into(),
        );
        // Mitsuba's defaults, so that a camera inside geometry sees what Mitsuba's does; the
        // far clip is checked to cut nothing when the scene loads (`load.rs`, `far_clips`).
        let near = p.float("near_clip")?.unwrap_or(0.01);
        let far = p.float("far_clip")?.unwrap_or(1e4);
        if !(near.is_finite() && near > 0.0 && far > near) {
            return Err(p.error(format!(
                "near_clip {near} and far_clip {far}: need 0 < near_clip < far_clip"
            )));
        }
        cam.insert("near_clip".into(), near.into());
        cam.insert("far_clip".into(), far.into());
        if ty == "thinlens" {
            let r = p.float("aperture_radius")?.unwrap_or(0.03);
            cam.insert("aperture".into(), r.into());
            let f = p.float("focus_distance")?.unwrap_or(0.0);
            if f > 0.0 {
                cam.insert("focus_distance".into(), f.into());
            } else {
                return Err(p.error("thinlens needs a positive focus_distance"));
            }
        } else {
            // Mitsuba's perspective camera has no lens: its focus distance does nothing.
            p.accept("focus_distance");
        }
        for s in p.objects("sampler") {
            self.sampler(s)?;
        }
        p.finish(self.warnings)?;
        self.cameras.push(cam);
        Ok(())
    }

    fn film(&mut self, f: &Node, cam: &mut Table) -> Result<(i64, i64), SceneError> {
        let p = Props::new(f);
        if f.plugin()? != "hdrfilm" {
            return Err(p.error("only hdrfilm is supported"));
        }
        let w = p.integer("width")?.unwrap_or(768);
        let h = p.integer("height")?.unwrap_or(576);
        let crop_x = p.integer("crop_offset_x")?.unwrap_or(0);
        let crop_y = p.integer("crop_offset_y")?.unwrap_or(0);
        let crop_w = p.integer("crop_width")?.unwrap_or(w);
        let crop_h = p.integer("crop_height")?.unwrap_or(h);
        if (crop_x, crop_y, crop_w, crop_h) != (0, 0, w, h) {
            let fits = crop_x >= 0
                && crop_y >= 0
                && crop_w > 0
                && crop_h > 0
                && crop_x + crop_w <= w
                && crop_y + crop_h <= h;
            if !fits {
                return Err(p.error(format!(
                    "crop window {crop_w}x{crop_h} at ({crop_x}, {crop_y}) does not fit the \
                     {w}x{h} film"
                )));
            }
            let v = [crop_x, crop_y, crop_w, crop_h].map(Value::Integer);
            cam.insert("crop".into(), Value::Array(v.to_vec()));
        }
        let filters = p.objects("rfilter");
        let filter = match filters.as_slice() {
            // Mitsuba's default reconstruction filter, splatted as Mitsuba applies it.
            [] => "gaussian:splat".to_string(),
            [r] => pixel_filter(r, self.warnings)?,
            _ => return Err(p.error("has more than one <rfilter>")),
        };
        cam.insert("pixel_filter".into(), filter.into());
        for key in ["file_format", "pixel_format", "component_format", "banner"] {
            p.ignore(key, "the output format is chosen by `-o`");
        }
        p.ignore(
            "high_quality_edges",
            "edge pixels see only samples inside the image",
        );
        p.ignore(
            "sample_border",
            "edge pixels see only samples inside the image",
        );
        p.finish(self.warnings)?;
        Ok((w, h))
    }

    fn sampler(&mut self, s: &Node) -> Result<(), SceneError> {
        let p = Props::new(s);
        let ty = s.plugin()?;
        if let Some(n) = p.integer("sample_count")? {
            if n < 1 {
                return Err(p.error(format!("sample_count {n}: must be at least 1")));
            }
            self.render.insert("spp".into(), n.into());
        }
        if let Some(seed) = p.integer("seed")? {
            self.render.insert("seed".into(), seed.max(0).into());
        }
        if ty != "independent" {
            self.warnings.push(s.at.warning(format!(
                "sampler \"{ty}\" replaced by ours (the same expectation, different noise)"
            )));
            for key in ["jitter", "scramble_seed", "dimension"] {
                p.accept(key);
            }
        }
        p.finish(self.warnings)
    }

    fn shape(&mut self, n: &'a Node) -> Result<(), SceneError> {
        match n.plugin()? {
            // Converted when an instance places it.
            "shapegroup" => Ok(()),
            "instance" => self.instance(n),
            _ => {
                let name = n
                    .attr("id")
                    .map_or_else(|| format!("shape{}", self.geometry.len()), str::to_string);
                let g = self.geometry_table(n, name, true)?;
                self.geometry.push(g);
                Ok(())
            }
        }
    }

    /// An `instance`: one `[[instance]]` per shape of the group it names.
    fn instance(&mut self, n: &'a Node) -> Result<(), SceneError> {
        let p = Props::new(n);
        let group = match p.refs().as_slice() {
            [r] => resolve(&self.ids, r)?,
            _ => return Err(p.error("an instance names exactly one shapegroup by <ref id>")),
        };
        if group.tag != "shape" || group.attr("type") != Some("shapegroup") {
            return Err(p.error("an instance's <ref> must name a shapegroup"));
        }
        let m = p.transform("to_world")?.unwrap_or(DMat4::IDENTITY);
        p.finish(self.warnings)?;
        let members = self.shape_group(group)?;
        self.placed += 1;
        let name = n
            .attr("id")
            .map_or_else(|| format!("instance{}", self.placed - 1), str::to_string);
        for g in members {
            let mut t = Table::new();
            t.insert("name".into(), format!("{name}/{g}").into());
            t.insert("geometry".into(), g.into());
            if m != DMat4::IDENTITY {
                t.insert("transform".into(), matrix_table(&m));
            }
            self.instances.push(t);
        }
        Ok(())
    }

    /// The geometry names of a shape group's shapes, converting them the first time.
    fn shape_group(&mut self, group: &'a Node) -> Result<Vec<String>, SceneError> {
        if let Some(done) = self.groups.get(&(group as *const Node)) {
            return Ok(done.clone());
        }
        let p = Props::new(group);
        let id = group.attr("id").unwrap_or("shapegroup");
        let mut names = Vec::new();
        for (i, c) in p.objects("shape").into_iter().enumerate() {
            if matches!(c.plugin()?, "shapegroup" | "instance") {
                return Err(c.at.error("shape groups do not nest"));
            }
            let own = c
                .attr("id")
                .map_or_else(|| format!("shape{i}"), str::to_string);
            let name = format!("{id}/{own}");
            let g = self.geometry_table(c, name.clone(), false)?;
            self.geometry.push(g);
            names.push(name);
        }
        if names.is_empty() {
            return Err(p.error("the shapegroup holds no shape"));
        }
        p.finish(self.warnings)?;
        self.groups.insert(group as *const Node, names.clone());
        Ok(names)
    }

    /// The `[[geometry]]` table of a shape; `emitters` says whether it may carry an area
    /// emitter (not inside a shape group).
    fn geometry_table(
        &mut self,
        n: &'a Node,
        name: String,
        emitters: bool,
    ) -> Result<Table, SceneError> {
        let p = Props::new(n);
        let ty = n.plugin()?;
        let mut g = Table::new();
        g.insert("name".into(), name.clone().into());
        let mut m = p.transform("to_world")?.unwrap_or(DMat4::IDENTITY);
        match ty {
            "obj" | "ply" | "serialized" => {
                let file = p
                    .string("filename")?
                    .ok_or_else(|| p.error("has no filename"))?;
                g.insert("file".into(), (self.file_name)(file).into());
                if ty == "serialized" {
                    if let Some(i) = p.integer("shape_index")? {
                        let i = u32::try_from(i).map_err(|_| {
                            p.error(format!("shape_index {i}: must be at least 0"))
                        })?;
                        g.insert("shape_index".into(), i64::from(i).into());
                    }
                }
                if p.boolean("face_normals")? == Some(true) {
                    g.insert("smooth".into(), false.into());
                }
                // Mitsuba flips an OBJ's or PLY's v by default into its own convention (v = 0
                // at the top row); ours is the files' own (v = 0 at the bottom row), so only
                // `false` asks for a flip. (Serialized meshes store Mitsuba's convention.)
                if ty != "serialized" && p.boolean("flip_tex_coords")? == Some(false) {
                    g.insert("flip_v".into(), true.into());
                }
            }
            "cylinder" => {
                let r = p.float("radius")?.unwrap_or(1.0);
                if r <= 0.0 {
                    return Err(p.error(format!("radius {r}: must be positive")));
                }
                let p0 = p.point("p0")?.unwrap_or(DVec3::ZERO);
                let p1 = p.point("p1")?.unwrap_or(DVec3::Z);
                if p0 == p1 {
                    return Err(p.error("p0 and p1 must differ"));
                }
                g.insert("shape".into(), "cylinder".into());
                g.insert("p0".into(), arr(p0));
                g.insert("p1".into(), arr(p1));
                g.insert("radius".into(), r.into());
                g.insert("segments".into(), CYLINDER_SEGMENTS.into());
                // Mitsuba's parameterisation, in our v convention (see "rectangle").
                g.insert("flip_v".into(), true.into());
                self.warnings.push(n.at.warning(format!(
                    "shape \"cylinder\" tessellated into {} triangles",
                    2 * CYLINDER_SEGMENTS
                )));
            }
            "rectangle" => {
                g.insert("shape".into(), "quad".into());
                let corners = [[-1, -1], [1, -1], [1, 1], [-1, 1]]
                    .map(|[x, y]| arr(DVec3::new(x as f64, y as f64, 0.0)));
                g.insert("vertices".into(), Value::Array(corners.to_vec()));
                // The quad's uvs are Mitsuba's `((x + 1) / 2, (y + 1) / 2)`. Mitsuba reads a
                // bitmap with v = 0 at its top row, we at its bottom row (the OBJ files'
                // convention, which Mitsuba flips into its own): our v is Mitsuba's 1 − v.
                g.insert("flip_v".into(), true.into());
            }
            "cube" => {
                g.insert("shape".into(), "box".into());
                g.insert("min".into(), arr(DVec3::splat(-1.0)));
                g.insert("max".into(), arr(DVec3::splat(1.0)));
            }
            "disk" => {
                g.insert("shape".into(), "disk".into());
                g.insert("radius".into(), 1.0.into());
                g.insert("normal".into(), arr(DVec3::Z));
            }
            "sphere" => {
                let c = p.point("center")?.unwrap_or(DVec3::ZERO);
                let r = p.float("radius")?.unwrap_or(1.0);
                if r <= 0.0 {
                    return Err(p.error(format!("radius {r}: must be positive")));
                }
                m = m * DMat4::from_translation(c) * DMat4::from_scale(DVec3::splat(r));
                g.insert("shape".into(), "sphere".into());
                g.insert("radius".into(), 1.0.into());
                g.insert("subdivisions".into(), SPHERE_SUBDIVISIONS.into());
                self.warnings.push(n.at.warning(format!(
                    "shape \"sphere\" tessellated into {} triangles",
                    20 * 4i64.pow(SPHERE_SUBDIVISIONS as u32)
                )));
            }
            other => {
                return Err(n.at.error(format!(
                    "shape \"{other}\" is not supported (obj, ply, serialized, rectangle, cube, disk, sphere and cylinder are)"
                )))
            }
        }
        if p.boolean("flip_normals")? == Some(true) {
            g.insert("flip_normals".into(), true.into());
        }
        if m != DMat4::IDENTITY {
            g.insert("transform".into(), matrix_table(&m));
        }
        let mut bsdfs: Vec<&'a Node> = p.objects("bsdf");
        for r in p.refs() {
            let target = resolve(&self.ids, r)?;
            if target.tag != "bsdf" {
                return Err(r.at.error(format!(
                    "<ref id=\"{}\"> names a <{}>, a shape takes a <bsdf>",
                    r.attr("id").unwrap_or(""),
                    target.tag
                )));
            }
            bsdfs.push(target);
        }
        // Our sphere has no uvs, and our cube's and disk's are not Mitsuba's: say so rather
        // than render other texels than Mitsuba does.
        if matches!(ty, "sphere" | "cube" | "disk")
            && bsdfs.iter().any(|b| reads_texture(&self.ids, b))
        {
            self.warnings.push(n.at.warning(format!(
                "shape \"{ty}\": its texture coordinates are not Mitsuba's, so its BSDF's \
                 textures read other texels than in Mitsuba"
            )));
        }
        let (base, table) = match bsdfs.as_slice() {
            [] => default_material(),
            [b] => self.material(b)?,
            _ => return Err(p.error("has more than one BSDF")),
        };
        let material = match p.objects("emitter").as_slice() {
            [] => self.use_material(base, table),
            [e] if emitters => self.emissive(e, table, &name)?,
            [e] => {
                return Err(e
                    .at
                    .error("an emitter inside a shapegroup is not supported"))
            }
            _ => return Err(p.error("has more than one emitter")),
        };
        g.insert("material".into(), material.into());
        p.finish(self.warnings)?;
        Ok(g)
    }

    /// An area emitter on a shape: a copy of the shape's material with `emission`.
    fn emissive(&mut self, e: &Node, mut table: Table, shape: &str) -> Result<String, SceneError> {
        let p = Props::new(e);
        if e.plugin()? != "area" {
            return Err(p.error("only area emitters can sit on a shape"));
        }
        let radiance = p
            .rgb("radiance", Role::Emission)?
            .ok_or_else(|| p.error("has no radiance"))?;
        p.finish(self.warnings)?;
        table.insert(
            "emission".into(),
            Value::Array(radiance.iter().map(|&v| Value::Float(v)).collect()),
        );
        Ok(self.use_material(format!("{shape}-emitter"), table))
    }

    /// Adds material `name` to the document the first time a shape uses it.
    fn use_material(&mut self, name: String, mut table: Table) -> String {
        if self.used.insert(name.clone()) {
            table.insert("name".into(), name.clone().into());
            self.materials.push(table);
        }
        name
    }

    /// The name and table of a BSDF element, converted once.
    fn material(&mut self, b: &'a Node) -> Result<(String, Table), SceneError> {
        if let Some(done) = self.by_node.get(&(b as *const Node)) {
            return Ok(done.clone());
        }
        let ids = &self.ids;
        let converted = bsdf::convert(b, &|r| resolve(ids, r), self.warnings)?;
        let name = b
            .attr("id")
            .map_or_else(|| format!("bsdf{}", self.by_node.len()), str::to_string);
        let mut t = self.table_of(&converted);
        if !converted.parts.is_empty() {
            // A blend's BSDFs: materials of their own, listed before it.
            let mut names = Vec::new();
            for (i, part) in converted.parts.iter().enumerate() {
                let part_name = format!("{name}.{i}");
                let table = self.table_of(part);
                names.push(toml::Value::from(self.use_material(part_name, table)));
            }
            t.insert("bsdfs".into(), toml::Value::Array(names));
        }
        let done = (name, t);
        self.by_node.insert(b as *const Node, done.clone());
        Ok(done)
    }

    /// The material table of a converted BSDF, its textures' file names mapped.
    fn table_of(&self, c: &bsdf::Converted) -> Table {
        let mut t = c.table.clone();
        for tex in &c.textures {
            t.insert(tex.key.into(), tex.value(self.file_name));
        }
        t
    }

    /// `constant` and `envmap` light the scene from every direction; other emitters outside
    /// shapes are not supported yet.
    fn environment(&mut self, e: &Node) -> Result<(), SceneError> {
        let p = Props::new(e);
        match e.plugin()? {
            "constant" => {
                let c = match p.color("radiance", Role::Emission)? {
                    Some(Color::Rgb(c)) => c,
                    None => [1.0; 3],
                    Some(Color::Texture(t)) => {
                        return Err(t.at.error("a textured constant emitter is not supported"))
                    }
                };
                if self.environment.is_some() {
                    return Err(p.error("a second environment emitter"));
                }
                let mut t = Table::new();
                t.insert(
                    "color".into(),
                    Value::Array(c.iter().map(|&v| Value::Float(v)).collect()),
                );
                self.environment = Some(t);
            }
            "envmap" => {
                let file = p
                    .string("filename")?
                    .ok_or_else(|| p.error("has no filename"))?;
                let lower = file.to_ascii_lowercase();
                if !lower.ends_with(".exr") && !lower.ends_with(".hdr") {
                    return Err(p.error(format!(
                        "\"{file}\": only OpenEXR and Radiance .hdr maps are supported"
                    )));
                }
                if self.environment.is_some() {
                    return Err(p.error("a second environment emitter"));
                }
                let mut t = Table::new();
                t.insert("map".into(), (self.file_name)(file).into());
                if let Some(scale) = p.float("scale")? {
                    t.insert("strength".into(), scale.into());
                }
                let m = p.transform("to_world")?.unwrap_or(DMat4::IDENTITY);
                let r = glam::DMat3::from_mat4(m);
                let orthonormal = (r * r.transpose() - glam::DMat3::IDENTITY)
                    .to_cols_array()
                    .iter()
                    .all(|v| v.abs() < 1e-4);
                if !orthonormal || r.determinant() < 0.0 {
                    return Err(p.error("to_world must be a rotation"));
                }
                // Our map is Mitsuba's turned half a turn about +y (docs/scene-format.md,
                // `tools/reference/toml_to_mitsuba.py`): world → our map frame is S·M⁻¹.
                let s = glam::DMat3::from_diagonal(DVec3::new(-1.0, 1.0, -1.0));
                let to_map = s * r.transpose();
                let identity = (to_map - glam::DMat3::IDENTITY)
                    .to_cols_array()
                    .iter()
                    .all(|v| v.abs() < 1e-9);
                if !identity {
                    let rows: Vec<Value> = (0..3).map(|i| arr(to_map.row(i))).collect();
                    t.insert("rotation".into(), Value::Array(rows));
                }
                self.environment = Some(t);
            }
            kind @ ("point" | "spot" | "directional") => {
                let light = delta_light(&p, kind)?;
                self.lights.push(light);
            }
            other => {
                return Err(e.at.error(format!(
                    "emitter \"{other}\" is not supported (area emitters on shapes, constant, envmap, point, spot and directional are)"
                )))
            }
        }
        p.finish(self.warnings)
    }
}

/// The `[[light]]` table of a `point`, `spot` or `directional` emitter, with Mitsuba 3's
/// parameters and defaults (`src/emitters/point.cpp`, `spot.cpp`, `directional.cpp`): a
/// point's `position` or `to_world` translation; a spot at `to_world`'s origin shining along
/// its +z, `cutoff_angle` 20° and `beam_width` ¾ of it by default; a directional light
/// travelling along `direction` or `to_world`'s +z. Colours default to 1 and are reduced as
/// emission (illuminant spectra, [`Role::Emission`]).
fn delta_light(p: &Props, kind: &str) -> Result<Table, SceneError> {
    let mut t = Table::new();
    t.insert("type".into(), kind.into());
    let colour = |name: &str| -> Result<Value, SceneError> {
        let c = p.rgb(name, Role::Emission)?.unwrap_or([1.0; 3]);
        Ok(arr(DVec3::from_array(c)))
    };
    let to_world = p.transform("to_world")?;
    // The one of `name` (a point or vector) and `to_world` given, as Mitsuba allows only one.
    let exclusive = |name: &str| -> Result<Option<DVec3>, SceneError> {
        let v = p.point(name)?;
        if v.is_some() && to_world.is_some() {
            return Err(p.error(format!("give `{name}` or `to_world`, not both")));
        }
        Ok(v)
    };
    let m = to_world.unwrap_or(DMat4::IDENTITY);
    let axis = || -> Result<DVec3, SceneError> {
        // A spot's cone is the inverse transform's (Mitsuba); ours keeps only the axis, so
        // the linear part must not scale unevenly or shear.
        let r = glam::DMat3::from_mat4(m);
        let g = r.transpose() * r;
        let s = g.x_axis.x;
        let conformal = s > 0.0
            && (g - glam::DMat3::from_diagonal(DVec3::splat(s)))
                .to_cols_array()
                .iter()
                .all(|v| v.abs() < 1e-4 * s);
        if !conformal || m.row(3) != DVec4::W {
            return Err(p.error("to_world must be a rotation, translation and uniform scale"));
        }
        Ok(m.transform_vector3(DVec3::Z).normalize())
    };
    match kind {
        "point" => {
            let position = exclusive("position")?.unwrap_or(m.transform_point3(DVec3::ZERO));
            t.insert("position".into(), arr(position));
            t.insert("intensity".into(), colour("intensity")?);
        }
        "spot" => {
            let cutoff = p.float("cutoff_angle")?.unwrap_or(20.0);
            let beam = p.float("beam_width")?.unwrap_or(cutoff * 0.75);
            if !(cutoff > 0.0 && cutoff <= 180.0 && beam >= 0.0 && beam <= cutoff) {
                return Err(p.error(format!(
                    "cutoff_angle {cutoff} and beam_width {beam}: need 0 < cutoff_angle ≤ 180 and 0 ≤ beam_width ≤ cutoff_angle"
                )));
            }
            t.insert("position".into(), arr(m.transform_point3(DVec3::ZERO)));
            t.insert("direction".into(), arr(axis()?));
            t.insert("intensity".into(), colour("intensity")?);
            t.insert("cutoff_angle".into(), cutoff.into());
            t.insert("beam_width".into(), beam.into());
        }
        _ => {
            let direction = match exclusive("direction")? {
                Some(d) if d.length() > 0.0 && d.is_finite() => d.normalize(),
                Some(_) => return Err(p.error("direction must be a non-zero vector")),
                None => axis()?,
            };
            t.insert("direction".into(), arr(direction));
            t.insert("irradiance".into(), colour("irradiance")?);
        }
    }
    Ok(t)
}

/// Position, view direction and up vector of a sensor's `to_world`, which must be rigid:
/// our cameras cannot scale, shear or mirror the image.
fn camera_frame(p: &Props, m: &DMat4) -> Result<(DVec3, DVec3, DVec3), SceneError> {
    let left = m.transform_vector3(DVec3::X);
    let up = m.transform_vector3(DVec3::Y);
    let dir = m.transform_vector3(DVec3::Z);
    let pos = m.transform_point3(DVec3::ZERO);
    let unit = |v: DVec3| (v.length() - 1.0).abs() < 1e-3;
    let orthogonal =
        left.dot(up).abs() < 1e-3 && up.dot(dir).abs() < 1e-3 && dir.dot(left).abs() < 1e-3;
    if !(unit(left) && unit(up) && unit(dir) && orthogonal) || m.row(3) != DVec4::W {
        return Err(
            p.error("to_world must be a rotation and translation (no scale, shear or projection)")
        );
    }
    if up.cross(dir).dot(left) < 0.0 {
        return Err(p.error("to_world mirrors the image, which our cameras cannot"));
    }
    Ok((pos, dir.normalize(), up.normalize()))
}

/// Mitsuba's field of view along `axis` as our vertical one.
fn vertical_fov(p: &Props, fov: f64, axis: &str, w: f64, h: f64) -> Result<f64, SceneError> {
    if !(fov > 0.0 && fov < 180.0) {
        return Err(p.error(format!("fov {fov}: must be in (0, 180)")));
    }
    let t = (fov.to_radians() / 2.0).tan();
    let vertical_tan = match axis {
        "x" => t * h / w,
        "y" => t,
        "smaller" if w < h => t * h / w,
        "smaller" => t,
        "larger" if w > h => t * h / w,
        "larger" => t,
        "diagonal" => t * h / (w * w + h * h).sqrt(),
        other => {
            return Err(p.error(format!(
                "fov_axis \"{other}\" is not one of x, y, smaller, larger, diagonal"
            )))
        }
    };
    Ok((2.0 * vertical_tan.atan()).to_degrees())
}

/// `focal_length = "50mm"`: the horizontal field of view of a 36 mm wide film.
fn focal_length_fov(p: &Props, text: &str) -> Result<f64, SceneError> {
    let mm: f64 = text
        .trim()
        .trim_end_matches("mm")
        .parse()
        .ok()
        .filter(|v: &f64| *v > 0.0)
        .ok_or_else(|| p.error(format!("focal_length \"{text}\" is not like \"50mm\"")))?;
    Ok((2.0 * (18.0 / mm).atan()).to_degrees())
}

/// An `<rfilter>` as our `pixel_filter` option string: the tent and the Gaussian splatted
/// into the pixels under them, as Mitsuba's `ImageBlock` does (so the noise, not only the
/// image, is Mitsuba's).
fn pixel_filter(r: &Node, warnings: &mut Vec<String>) -> Result<String, SceneError> {
    let p = Props::new(r);
    let spec = match r.plugin()? {
        "box" => "box".to_string(),
        "tent" => match p.float("radius")? {
            Some(radius) => format!("tent:radius={radius}:splat"),
            None => "tent:splat".into(),
        },
        "gaussian" => match p.float("stddev")? {
            Some(s) => format!("gaussian:stddev={s}:splat"),
            None => "gaussian:splat".into(),
        },
        other => {
            return Err(r.at.error(format!(
                "rfilter \"{other}\" is not supported (box, tent and gaussian are)"
            )))
        }
    };
    p.finish(warnings)?;
    Ok(spec)
}

/// Mitsuba's BSDF for a shape without one: diffuse, reflectance 0.5.
fn default_material() -> (String, Table) {
    let mut t = Table::new();
    t.insert("type".into(), "diffuse".into());
    t.insert("color".into(), arr(DVec3::splat(0.5)));
    ("default-diffuse".into(), t)
}
