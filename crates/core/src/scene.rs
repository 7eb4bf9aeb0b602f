//! The runtime scene: triangles with their attributes, materials, lights, environment, cameras.
//!
//! This is plain data filled in by `rt-scene` (from TOML and mesh files) or by tests. Triangles
//! are stored flat, in file order, so a triangle index is the same everywhere: in `Hit::prim`,
//! in material associations and in the light sampler.
//!
//! Instances ([`crate::instance`]) are prototypes placed by (possibly animated) transforms;
//! their world copies at the scene's current time ([`Scene::set_time`]) sit in the same flat
//! arrays, one range per instance, so a triangle index still means one thing everywhere.

use crate::{
    animation::{CameraMotion, MaterialMotion, Motion},
    bump::{self, NormalPerturbation},
    delta_light::DeltaLight,
    environment::Environment,
    instance::{place_attributes, place_triangle, placement_error, Instance, Prototype},
    lights::LightSampler,
    texture::Texture,
    transform::Transform,
    triangle, Camera, Hit, Material, Rgb,
};
use glam::{Vec2, Vec3};
use std::sync::OnceLock;

/// A named group of consecutive triangles (one `[[geometry]]` entry).
#[derive(Clone, Debug, PartialEq)]
pub struct Object {
    /// Name from the scene file.
    pub name: String,
    /// Index of the first triangle.
    pub first: u32,
    /// Number of triangles.
    pub count: u32,
}

/// Everything needed to render.
#[derive(Clone, Debug)]
pub struct Scene {
    /// World-space vertex positions, three per triangle.
    pub triangles: Vec<[Vec3; 3]>,
    /// Optional per-vertex shading normals (world space, unit), per triangle: one entry per
    /// triangle, or none at all when no triangle has normals ([`Scene::compact_attributes`]).
    /// Read them with [`Scene::normals_of`].
    pub normals: Vec<Option<[Vec3; 3]>>,
    /// Optional per-vertex texture coordinates, per triangle; one entry per triangle or none at
    /// all, like `normals`. Read them with [`Scene::uvs_of`].
    pub uvs: Vec<Option<[Vec2; 3]>>,
    /// Material index of every triangle.
    pub material_ids: Vec<u32>,
    /// Materials.
    pub materials: Vec<Material>,
    /// Textures referenced by materials.
    pub textures: Vec<Texture>,
    /// Distant illumination.
    pub environment: Environment,
    /// Point, spot and directional lights.
    pub delta_lights: Vec<DeltaLight>,
    /// Cameras; the first is the default.
    pub cameras: Vec<Camera>,
    /// Named triangle ranges (instances' world copies included).
    pub objects: Vec<Object>,
    /// Geometries in object space that instances place.
    pub prototypes: Vec<Prototype>,
    /// Placed prototypes, in the order of their world ranges.
    pub instances: Vec<Instance>,
    /// Keyframed cameras.
    pub camera_motions: Vec<CameraMotion>,
    /// Materials whose emission is keyed ([`Scene::set_time`] writes it into `materials`).
    pub material_motions: Vec<MaterialMotion>,
    /// The time (seconds) the world copies and cameras are at ([`Scene::set_time`]).
    pub time: f32,
    /// How long (seconds) the shutter stays open after `time`: 0 renders the instant `time`;
    /// more blurs what moves (a ray's [`crate::Ray::time`] is a fraction of this interval).
    pub shutter: f32,
    /// Emitter sampling structure, built on first use ([`Scene::lights`]), so integrators that
    /// never sample lights never pay for it. Reset with [`Scene::build_lights`] after changing
    /// geometry, materials or the environment.
    lights: OnceLock<LightSampler>,
}

/// Shading information at a ray hit.
#[derive(Clone, Copy, Debug)]
pub struct SurfaceHit {
    /// Position, reconstructed from barycentrics.
    pub p: Vec3,
    /// Per-axis bound on how far ray queries may misplace `p` relative to its triangle
    /// ([`triangle::point_with_error`]); spawned rays start this far off the surface
    /// ([`crate::ray::offset_ray_origin`]).
    pub p_error: Vec3,
    /// Unit geometric normal of the front (counter-clockwise) face.
    pub ng: Vec3,
    /// Unit shading normal, on the same side as `ng`.
    pub ns: Vec3,
    /// Texture coordinates (barycentrics when the mesh has none).
    pub uv: Vec2,
    /// Material index.
    pub material: u32,
    /// Triangle index.
    pub prim: u32,
    /// The instance the triangle belongs to, if any.
    pub instance: Option<u32>,
    /// When the ray that found the point was traced, as a fraction of the shutter
    /// ([`crate::Ray::time`]); rays leaving the point keep it ([`SurfaceHit::spawn_ray`]).
    pub time: f32,
}

impl SurfaceHit {
    /// A ray leaving the point along `w`, offset off the surface, at the point's time.
    #[inline]
    pub fn spawn_ray(&self, w: Vec3) -> crate::Ray {
        crate::ray::spawn_ray(self.p, self.p_error, self.ng, w).at_time(self.time)
    }

    /// The shadow segment from the point to point `q` (error bound `q_error`, normal `nq`) on
    /// another surface, at the point's time ([`crate::ray::shadow_segment`]).
    #[inline]
    pub fn shadow_segment(&self, q: Vec3, q_error: Vec3, nq: Vec3) -> (crate::Ray, f32) {
        let (r, t_max) = crate::ray::shadow_segment(self.p, self.p_error, self.ng, q, q_error, nq);
        (r.at_time(self.time), t_max)
    }
}

impl Scene {
    /// An empty scene with a black environment.
    pub fn empty() -> Self {
        Self {
            triangles: Vec::new(),
            normals: Vec::new(),
            uvs: Vec::new(),
            material_ids: Vec::new(),
            materials: Vec::new(),
            textures: Vec::new(),
            environment: Environment::Constant(Rgb::ZERO),
            delta_lights: Vec::new(),
            cameras: Vec::new(),
            objects: Vec::new(),
            prototypes: Vec::new(),
            instances: Vec::new(),
            camera_motions: Vec::new(),
            material_motions: Vec::new(),
            time: 0.0,
            shutter: 0.0,
            lights: OnceLock::new(),
        }
    }

    /// Appends a triangle with material `material` and no shading normals or uvs.
    pub fn push_triangle(&mut self, v: [Vec3; 3], material: u32) {
        // A full attribute list stays full; a compacted (empty) one stays empty.
        if self.normals.len() == self.triangles.len() {
            self.normals.push(None);
        }
        if self.uvs.len() == self.triangles.len() {
            self.uvs.push(None);
        }
        self.triangles.push(v);
        self.material_ids.push(material);
    }

    /// Drops the per-triangle normal and uv lists when no triangle has any, so a mesh without
    /// them holds 68 bytes less per triangle and shading reads nothing for them (on the
    /// dragon, the load of an absent normal was a cache miss on every hit).
    pub fn compact_attributes(&mut self) {
        if self.normals.iter().all(Option::is_none) {
            self.normals = Vec::new();
        }
        if self.uvs.iter().all(Option::is_none) {
            self.uvs = Vec::new();
        }
    }

    /// Shading normals of triangle `i`, if it has them.
    #[inline]
    pub fn normals_of(&self, i: usize) -> Option<&[Vec3; 3]> {
        self.normals.get(i).and_then(Option::as_ref)
    }

    /// Texture coordinates of triangle `i`, if it has them.
    #[inline]
    pub fn uvs_of(&self, i: usize) -> Option<&[Vec2; 3]> {
        self.uvs.get(i).and_then(Option::as_ref)
    }

    /// Rebuilds the light sampler from the emissive triangles and the environment now.
    pub fn build_lights(&mut self) {
        self.lights = OnceLock::from(LightSampler::build(self));
    }

    /// The light sampler, built from the emissive triangles and the environment on first use.
    #[inline]
    pub fn lights(&self) -> &LightSampler {
        self.lights.get_or_init(|| LightSampler::build(self))
    }

    /// The light sampler if something has used (or [`Scene::build_lights`] built) it.
    pub fn lights_if_built(&self) -> Option<&LightSampler> {
        self.lights.get()
    }

    /// True if something emits at some time: a triangle the light sampler would sample, a
    /// triangle whose material's keyed emission is lit at some key, a delta light, or a
    /// non-black environment. Cheap (no light sampler is built), for warnings about black
    /// images.
    pub fn has_light_sources(&self) -> bool {
        !self.environment.is_black()
            || self.delta_lights.iter().any(DeltaLight::emits)
            || (0..self.triangles.len() as u32).any(|i| crate::lights::is_emitter(self, i))
            || self.material_motions.iter().any(|m| {
                m.keys().iter().any(|k| k.emission.max_element() > 0.0)
                    && self.material_ids.contains(&(m.material as u32))
            })
    }

    /// The camera named `name`, or the first when `name` is `None`: the one camera-by-name
    /// lookup (callers add their own error).
    pub fn camera(&self, name: Option<&str>) -> Option<&Camera> {
        match name {
            Some(name) => self.cameras.iter().find(|c| c.name == name),
            None => self.cameras.first(),
        }
    }

    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// Material of triangle `prim`.
    #[inline]
    pub fn material_of(&self, prim: u32) -> &Material {
        &self.materials[self.material_ids[prim as usize] as usize]
    }

    /// Shading information for a hit of a ray traced at shutter time `time` (the ray's
    /// [`crate::Ray::time`]; 0 without motion blur). A moving instance is shaded where it was
    /// at that time, from its prototype, not from its world copy at the shutter's opening.
    #[inline]
    pub fn surface(&self, hit: &Hit, time: f32) -> SurfaceHit {
        let i = hit.prim as usize;
        let instance = self.instance_of(hit.prim);
        let moved = match instance {
            Some(k) if time != 0.0 && self.shutter > 0.0 => self.moved_triangle(k, i, time),
            _ => None,
        };
        let v = match &moved {
            Some((v, _, _)) => v,
            None => &self.triangles[i],
        };
        let (b1, b2) = (hit.b1, hit.b2);
        let b0 = 1.0 - b1 - b2;
        let (p, p_error) = triangle::point_with_error(v, b1, b2);
        let ng = triangle::geometric_normal(v).normalize_or(Vec3::Z);
        let normals = match &moved {
            Some((_, n, _)) => n.as_ref(),
            None => self.normals_of(i),
        };
        let ns = match normals {
            Some(n) => {
                let n = (n[0] * b0 + n[1] * b1 + n[2] * b2).normalize_or(ng);
                if n.dot(ng) < 0.0 {
                    -n
                } else {
                    n
                }
            }
            None => ng,
        };
        let uvs = self.uvs_of(i);
        let uv = match uvs {
            Some(t) => t[0] * b0 + t[1] * b1 + t[2] * b2,
            None => Vec2::new(b1, b2),
        };
        let material = self.material_ids[i];
        let ns = match self.materials[material as usize].perturbation {
            Some(pert) => self.perturbed_normal(pert, v, uvs, ns, ng, uv),
            None => ns,
        };
        // A two-level structure intersects the prototype with an inverse-transformed ray:
        // the origin offset must also cover the placement's rounding.
        let p_error = match instance {
            Some(k) => {
                let inst = &self.instances[k as usize];
                let local = (hit.prim - inst.first) as usize;
                let object = &self.prototypes[inst.prototype as usize].triangles[local];
                let placement = match &moved {
                    Some((_, _, t)) => t,
                    None => &inst.transform,
                };
                p_error + placement_error(placement, object, p)
            }
            None => p_error,
        };
        SurfaceHit {
            p,
            p_error,
            ng,
            ns,
            uv,
            material,
            prim: hit.prim,
            instance,
            time,
        }
    }

    /// The shading normal `ns` bent by a bump or normal map, at texture coordinates `uv` of
    /// the triangle with vertices `v` and uvs `uvs` (barycentrics when it has none, whose
    /// tangents are the edges).
    fn perturbed_normal(
        &self,
        pert: NormalPerturbation,
        v: &[Vec3; 3],
        uvs: Option<&[Vec2; 3]>,
        ns: Vec3,
        ng: Vec3,
        uv: Vec2,
    ) -> Vec3 {
        const BARYCENTRIC: [Vec2; 3] = [Vec2::ZERO, Vec2::X, Vec2::Y];
        let (dpdu, dpdv) = bump::triangle_tangents(v, uvs.unwrap_or(&BARYCENTRIC), ng);
        match pert {
            NormalPerturbation::Bump { texture, scale } => {
                let (_, grad) = self.textures[texture as usize].scalar_gradient(uv);
                bump::bumped_normal(ns, ng, dpdu, dpdv, grad * scale)
            }
            NormalPerturbation::NormalMap { texture } => {
                let rgb = self.textures[texture as usize].lookup(uv);
                bump::mapped_normal(ns, ng, dpdu, rgb)
            }
        }
    }

    /// Triangle `i` of instance `k` (its vertices and shading normals in the world, and the
    /// placement) at shutter time `time`, if the instance is elsewhere then than its world
    /// copy.
    fn moved_triangle(
        &self,
        k: u32,
        i: usize,
        time: f32,
    ) -> Option<([Vec3; 3], Option<[Vec3; 3]>, Transform)> {
        let inst = &self.instances[k as usize];
        if !inst.is_animated() {
            return None;
        }
        let t = inst.transform_at(self.time + time * self.shutter);
        let proto = &self.prototypes[inst.prototype as usize];
        let local = i - inst.first as usize;
        let flip = t.flips_handedness();
        let v = place_triangle(&t, flip, &proto.triangles[local]);
        let normals = proto.normals.get(local).copied().flatten();
        let (n, _) = place_attributes(&t, flip, normals, None);
        Some((v, n, t))
    }

    /// True if something moves while the shutter is open: an instance, or the camera named
    /// `camera` (see [`Scene::camera_motion`]). Renders then draw a time per camera sample.
    pub fn is_motion_blurred(&self, camera: &str) -> bool {
        self.instances.iter().any(|i| self.moves_in_shutter(i))
            || self.camera_motion(camera).is_some()
    }

    /// True if instance `inst` moves while the shutter is open.
    fn moves_in_shutter(&self, inst: &Instance) -> bool {
        self.shutter > 0.0 && inst.moves_during(self.time, self.time + self.shutter)
    }

    /// The keyframed motion of the camera named `camera`, if it has one and moves while the
    /// shutter is open.
    pub fn camera_motion(&self, camera: &str) -> Option<&CameraMotion> {
        self.camera_motions.iter().find(|m| {
            self.shutter > 0.0
                && self.cameras.get(m.camera).is_some_and(|c| c.name == camera)
                && m.spans(self.time, self.time + self.shutter)
        })
    }

    /// Why the scene cannot be motion blurred as it is, if it cannot: lights are sampled
    /// from the world copies at the shutter's opening, so an emitter that moves while the
    /// shutter is open would light the scene from the wrong place, and one whose emission
    /// changes would light it with the wrong power.
    pub fn motion_blur_error(&self) -> Option<MotionBlurError> {
        self.instances
            .iter()
            .find(|inst| {
                self.moves_in_shutter(inst)
                    && (inst.first..inst.first + inst.count)
                        .any(|p| crate::lights::is_emitter(self, p))
            })
            .map(|inst| MotionBlurError::MovingEmitter(inst.name.clone()))
            .or_else(|| {
                self.material_motions
                    .iter()
                    .find(|m| self.shutter > 0.0 && m.spans(self.time, self.time + self.shutter))
                    .map(|m| {
                        let name = self.materials.get(m.material).map(|x| x.name.clone());
                        MotionBlurError::AnimatedEmission(name.unwrap_or_default())
                    })
            })
    }

    /// The instance triangle `prim` belongs to, if any.
    #[inline]
    pub fn instance_of(&self, prim: u32) -> Option<u32> {
        if self.instances.is_empty() {
            return None;
        }
        let k = self.instances.partition_point(|i| i.first <= prim);
        let i = k.checked_sub(1)?;
        let inst = &self.instances[i];
        (prim - inst.first < inst.count).then_some(i as u32)
    }

    /// Reorders the triangles and everything stored per triangle (normals, uvs, material
    /// ids) so that triangle `i` is the one that was at `perm[i]`: what structures that live
    /// in the triangle order (IOSP) need, so that `Hit::prim` indexes the scene without an
    /// index map. The light table is rebuilt on next use. Object ranges cannot follow an
    /// arbitrary order, so the objects become one range over the whole scene, named after
    /// them when there was one.
    pub fn permute_triangles(&mut self, perm: &[u32]) -> Result<(), PermuteError> {
        let n = self.triangles.len();
        if !self.instances.is_empty() {
            return Err(PermuteError::Instances);
        }
        let mut seen = vec![false; n];
        if perm.len() != n
            || perm
                .iter()
                .any(|&p| (p as usize) >= n || std::mem::replace(&mut seen[p as usize], true))
        {
            return Err(PermuteError::NotAPermutation(n));
        }
        fn apply<T: Copy>(v: &mut Vec<T>, perm: &[u32]) {
            if !v.is_empty() {
                *v = perm.iter().map(|&p| v[p as usize]).collect();
            }
        }
        apply(&mut self.triangles, perm);
        apply(&mut self.normals, perm);
        apply(&mut self.uvs, perm);
        apply(&mut self.material_ids, perm);
        let name = match self.objects.as_slice() {
            [one] => one.name.clone(),
            _ => "permuted".to_string(),
        };
        self.objects = if n == 0 {
            Vec::new()
        } else {
            vec![Object {
                name,
                first: 0,
                count: n as u32,
            }]
        };
        self.lights = OnceLock::new();
        Ok(())
    }

    /// Adds a prototype (object-space geometry for instances) and returns its index.
    pub fn add_prototype(&mut self, p: Prototype) -> u32 {
        self.prototypes.push(p);
        (self.prototypes.len() - 1) as u32
    }

    /// Places prototype `prototype` by `base` (then `motion`), appending its world copy at the
    /// scene's current time to the flat arrays and an object of the same name; returns the
    /// instance's index.
    ///
    /// # Panics
    /// If `prototype` is not a prototype of this scene or the scene would exceed 2³² − 1
    /// triangles (loaders check both).
    pub fn add_instance(
        &mut self,
        name: impl Into<String>,
        prototype: u32,
        base: Transform,
        motion: Option<Motion>,
    ) -> u32 {
        let name = name.into();
        let first = self.triangles.len();
        let count = self.prototypes[prototype as usize].triangles.len();
        assert!(first + count <= u32::MAX as usize, "too many triangles");
        let mut inst = Instance {
            name: name.clone(),
            prototype,
            base,
            motion,
            transform: base,
            first: first as u32,
            count: count as u32,
        };
        inst.transform = inst.transform_at(self.time);
        let proto = &self.prototypes[prototype as usize];
        self.triangles.extend_from_slice(&proto.triangles);
        self.material_ids.extend_from_slice(&proto.material_ids);
        if !proto.normals.is_empty() {
            self.normals.resize(first, None);
            self.normals.extend_from_slice(&proto.normals);
        }
        if !proto.uvs.is_empty() {
            self.uvs.resize(first, None);
            self.uvs.extend_from_slice(&proto.uvs);
        }
        self.objects.push(Object {
            name,
            first: first as u32,
            count: count as u32,
        });
        self.instances.push(inst);
        let k = self.instances.len() - 1;
        self.write_world_copy(k);
        self.lights = OnceLock::new();
        k as u32
    }

    /// Rewrites instance `k`'s world copy from its prototype and current transform.
    fn write_world_copy(&mut self, k: usize) {
        let inst = &self.instances[k];
        let proto = &self.prototypes[inst.prototype as usize];
        let (t, flip) = (inst.transform, inst.transform.flips_handedness());
        let range = inst.first as usize..(inst.first + inst.count) as usize;
        for (w, v) in self.triangles[range.clone()]
            .iter_mut()
            .zip(&proto.triangles)
        {
            *w = place_triangle(&t, flip, v);
        }
        let has_normals = !proto.normals.is_empty() && !self.normals.is_empty();
        let has_uvs = !proto.uvs.is_empty() && !self.uvs.is_empty();
        for (j, i) in range.enumerate() {
            let n = if has_normals { proto.normals[j] } else { None };
            let uv = if has_uvs { proto.uvs[j] } else { None };
            let (n, uv) = place_attributes(&t, flip, n, uv);
            if has_normals {
                self.normals[i] = n;
            }
            if has_uvs {
                self.uvs[i] = uv;
            }
        }
    }

    /// Moves the animated instances and cameras to time `t` (seconds) and sets the keyed
    /// materials' emission: rewrites the world copies of the instances whose transform changed
    /// and resets the light table if any did or any emission changed (a lamp switched off
    /// leaves the table, so a frame without a lit emitter samples only the environment).
    /// Returns the indices of the instances that moved.
    pub fn set_time(&mut self, t: f32) -> Vec<u32> {
        self.time = t;
        let mut moved = Vec::new();
        for k in 0..self.instances.len() {
            let next = self.instances[k].transform_at(t);
            if next != self.instances[k].transform {
                self.instances[k].transform = next;
                self.write_world_copy(k);
                moved.push(k as u32);
            }
        }
        let mut relit = false;
        for m in &self.material_motions {
            let e = m.at(t);
            let material = &mut self.materials[m.material];
            if material.emission != e {
                material.emission = e;
                relit = true;
            }
        }
        if !moved.is_empty() || relit {
            self.lights = OnceLock::new();
        }
        for m in &self.camera_motions {
            let k = m.at(t);
            let old = &self.cameras[m.camera];
            let c = Camera::look_at(
                old.name.clone(),
                k.position,
                k.look_at,
                k.up,
                k.fov,
                old.width,
                old.height,
                old.aperture,
                old.focus_distance,
            );
            // A blend of two valid keys can still be degenerate (position crossing look_at):
            // keep the last good camera then.
            if c.forward.is_finite() && c.right.is_finite() && c.up.is_finite() {
                self.cameras[m.camera] = c;
            }
        }
        moved
    }

    /// What material `m`'s textures read at `uv`: its texture's colour (white without one)
    /// and its textured parameters; for a blend, where its BSDF will read its textures.
    #[inline]
    pub fn tint(&self, m: &Material, uv: Vec2) -> crate::tint::Tint<'_> {
        crate::tint::Tint {
            color: self.texture_color(m, uv),
            params: m.param_textures.lookup(&self.textures, uv),
            // A blend's textures and a textured index of refraction are read where the BSDF
            // is evaluated (`crate::tint`).
            at: (m.blend.is_some() || m.param_textures.has_ior())
                .then_some(crate::tint::TexturesAt { scene: self, uv }),
        }
    }

    /// The colour part of [`Scene::tint`] alone: all a plain Lambertian layer reads
    /// ([`Material::plain_lambert`]), without filling the textured parameters in.
    #[inline]
    pub fn texture_color(&self, m: &Material, uv: Vec2) -> Rgb {
        match m.texture {
            Some(t) => self.textures[t as usize].lookup(uv),
            None => Rgb::ONE,
        }
    }
}

/// Why a scene cannot be rendered with motion blur ([`Scene::motion_blur_error`]).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum MotionBlurError {
    /// An emitter moves while the shutter is open.
    #[error("`{0}` emits light and moves while the shutter is open: moving lights cannot be motion blurred (light sampling sees them where the shutter opens); render it with --shutter 0 or make it static")]
    MovingEmitter(String),
    /// A material's keyed emission changes while the shutter is open.
    #[error("material `{0}` has an animated emission that changes while the shutter is open: lights cannot be motion blurred (light sampling sees them as they are when the shutter opens); render it with --shutter 0 or move the shutter off the change")]
    AnimatedEmission(String),
}

/// Why [`Scene::permute_triangles`] refused.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum PermuteError {
    /// The order does not name every triangle exactly once.
    #[error("not a permutation of the scene's {0} triangles")]
    NotAPermutation(usize),
    /// Instances keep their world copies in contiguous ranges.
    #[error("the scene has instances, whose world copies must stay in contiguous ranges: structures that reorder the triangles (iosp0, iosp4, iosp2) cannot hold instanced or animated scenes; use two-level or clusters")]
    Instances,
}

/// Bytes a [`Scene`] holds, by kind (length × element size of each buffer, names included).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SceneMemory {
    /// Vertex positions, per-vertex normals and uvs, material ids, object records.
    pub geometry: usize,
    /// Materials with their names and layers.
    pub materials: usize,
    /// Texture texels.
    pub textures: usize,
    /// Environment map texels (its importance map is counted apart, as a sampling structure).
    pub environment: usize,
}

impl SceneMemory {
    /// All kinds together.
    pub fn total(&self) -> usize {
        self.geometry + self.materials + self.textures + self.environment
    }
}

impl Scene {
    /// What the scene's buffers hold. The light sampler and the environment's importance map
    /// are sampling structures built from the scene and are reported by their own
    /// `memory_bytes`, not here.
    pub fn memory(&self) -> SceneMemory {
        use std::mem::{size_of, size_of_val};
        let geometry = size_of_val(self.triangles.as_slice())
            + size_of_val(self.normals.as_slice())
            + size_of_val(self.uvs.as_slice())
            + size_of_val(self.material_ids.as_slice())
            + self
                .objects
                .iter()
                .map(|o| size_of::<Object>() + o.name.len())
                .sum::<usize>()
            + self
                .prototypes
                .iter()
                .map(|p| {
                    size_of_val(p.triangles.as_slice())
                        + size_of_val(p.normals.as_slice())
                        + size_of_val(p.uvs.as_slice())
                        + size_of_val(p.material_ids.as_slice())
                        + p.name.len()
                })
                .sum::<usize>()
            + self
                .instances
                .iter()
                .map(|i| size_of::<Instance>() + i.name.len())
                .sum::<usize>();
        let materials = self
            .materials
            .iter()
            .map(|m| size_of::<Material>() + m.name.len() + size_of_val(m.layers.as_slice()))
            .sum();
        let textures = self
            .textures
            .iter()
            .map(|t| size_of::<Texture>() + size_of_val(t.texels.as_slice()))
            .sum();
        SceneMemory {
            geometry,
            materials,
            textures,
            environment: self.environment.map().map_or(0, |m| m.texel_bytes()),
        }
    }
}

impl crate::content_hash::ContentHash for Object {
    fn content_hash(&self, out: &mut crate::content_hash::Sink<'_>) {
        let Object { name, first, count } = self;
        name.content_hash(out);
        first.content_hash(out);
        count.content_hash(out);
    }
}

impl crate::content_hash::ContentHash for Scene {
    /// Everything but the light sampler, which is built from the triangles and materials.
    fn content_hash(&self, out: &mut crate::content_hash::Sink<'_>) {
        let Scene {
            triangles,
            normals,
            uvs,
            material_ids,
            materials,
            textures,
            environment,
            delta_lights,
            cameras,
            objects,
            prototypes,
            instances,
            camera_motions,
            material_motions,
            time,
            shutter,
            lights: _,
        } = self;
        triangles.content_hash(out);
        normals.content_hash(out);
        uvs.content_hash(out);
        material_ids.content_hash(out);
        materials.content_hash(out);
        textures.content_hash(out);
        environment.content_hash(out);
        delta_lights.content_hash(out);
        cameras.content_hash(out);
        objects.content_hash(out);
        prototypes.content_hash(out);
        instances.content_hash(out);
        camera_motions.content_hash(out);
        material_motions.content_hash(out);
        time.content_hash(out);
        shutter.content_hash(out);
    }
}

#[cfg(test)]
mod memory_tests {
    use super::*;

    #[test]
    fn memory_counts_every_buffer_by_kind() {
        let mut s = Scene::empty();
        assert_eq!(s.memory(), SceneMemory::default());
        s.materials.push(Material::diffuse("ab", Rgb::ONE));
        s.push_triangle([Vec3::ZERO, Vec3::X, Vec3::Y], 0);
        s.push_triangle([Vec3::ZERO, Vec3::Y, Vec3::Z], 0);
        s.textures.push(Texture::new(2, 1, vec![Rgb::ONE; 2]));
        let m = s.memory();
        let per_tri = 36 + size_of::<Option<[Vec3; 3]>>() + size_of::<Option<[Vec2; 3]>>() + 4;
        assert_eq!(m.geometry, 2 * per_tri);
        let layer = size_of::<crate::Layer>();
        assert_eq!(m.materials, size_of::<Material>() + 2 + layer);
        assert_eq!(m.textures, size_of::<Texture>() + 24);
        assert_eq!(m.environment, 0);
        assert_eq!(m.total(), m.geometry + m.materials + m.textures);
    }
}
