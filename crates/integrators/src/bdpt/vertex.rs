//! Path vertices of bidirectional path tracing and the densities between them.
//!
//! Every density is stored in the measure the MIS weights compare: area at the vertex it
//! samples, except towards the environment, a vertex at infinity whose density stays a
//! solid-angle one (pbrt-v4's convention, `Vertex::ConvertDensity`).

use rt_core::{
    delta_light::DeltaLight, emission::plane_area, glam::Vec3, lights::LightSampler,
    material::Bsdf, Aabb, Camera, Material, Rgb, Scene,
};
use std::f32::consts::FRAC_1_PI;

/// What a vertex is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Kind {
    /// The lens point (or pinhole) a camera subpath starts at.
    Camera,
    /// A scattering point on a surface (it may emit too).
    Surface,
    /// The point on an emissive triangle a light subpath starts at, or a point or spot
    /// light's position ([`Vertex::delta_light`]).
    Light,
    /// The environment, at infinity: `p` holds the unit direction towards it (also a
    /// directional light's start, [`Vertex::delta_light`]).
    Env,
}

/// One vertex of a camera or light subpath.
pub(super) struct Vertex<'a> {
    pub kind: Kind,
    /// Position; for [`Kind::Env`] the unit direction from the scene towards the environment.
    pub p: Vec3,
    pub p_error: Vec3,
    /// Unit geometric normal of the front face (surfaces and emitters).
    pub ng: Vec3,
    /// Unit shading normal (surfaces).
    pub ns: Vec3,
    /// Unit direction towards the previous vertex of its subpath (surfaces).
    pub wo: Vec3,
    /// Throughput of the subpath up to and including this vertex's arrival.
    pub beta: Rgb,
    /// Density of this vertex when sampled from its subpath's side.
    pub pdf_fwd: f32,
    /// Density of this vertex when sampled from the other side.
    pub pdf_rev: f32,
    /// The subpath left this vertex through a delta lobe: no strategy connects here.
    pub delta: bool,
    /// The BSDF for `wo` (surfaces).
    pub bsdf: Option<Bsdf<'a>>,
    pub material: Option<&'a Material>,
    pub tint: rt_core::tint::Tint<'a>,
    /// Triangle index (surfaces and emitters), for the light sampler's pdf.
    pub prim: u32,
    /// Radiance the emitter leaves (light vertices).
    pub emission: Rgb,
    pub two_sided: bool,
    /// Random numbers the vertex's connection strategies use, drawn when the vertex was made
    /// so a vertex's dimensions do not depend on which strategies ran: next-event estimation
    /// (selection, point) on camera subpaths, the lens point on light subpaths.
    pub u_connect: [f32; 3],
    /// The delta light a light subpath starts at ([`Kind::Light`] for a point or spot,
    /// [`Kind::Env`] for a directional light): no camera-side strategy can find it.
    pub delta_light: Option<DeltaLight>,
}

impl<'a> Vertex<'a> {
    pub fn endpoint(kind: Kind, p: Vec3, beta: Rgb, pdf_fwd: f32) -> Self {
        Self {
            kind,
            p,
            p_error: Vec3::ZERO,
            ng: Vec3::ZERO,
            ns: Vec3::ZERO,
            wo: Vec3::ZERO,
            beta,
            pdf_fwd,
            pdf_rev: 0.0,
            delta: false,
            bsdf: None,
            material: None,
            tint: rt_core::tint::Tint::NONE,
            prim: u32::MAX,
            emission: Rgb::ZERO,
            two_sided: false,
            u_connect: [0.0; 3],
            delta_light: None,
        }
    }

    /// On a surface (with a normal that turns densities into area densities); a point or spot
    /// light is not.
    pub fn on_surface(&self) -> bool {
        matches!(self.kind, Kind::Surface | Kind::Light) && self.delta_light.is_none()
    }

    /// A scattering vertex a strategy may connect to: it has a non-delta lobe.
    pub fn connectible(&self) -> bool {
        self.bsdf.as_ref().is_some_and(Bsdf::has_non_delta)
    }

    /// An emissive surface (a camera subpath found a light).
    pub fn emits(&self) -> bool {
        self.material.is_some_and(Material::is_emissive)
    }

    /// Radiance leaving this vertex towards unit `w` if it is a light (emissive surface or
    /// the environment, for which `w` is ignored).
    pub fn le(&self, scene: &Scene, w: Vec3) -> Rgb {
        match self.kind {
            Kind::Env => scene.environment.radiance(self.p),
            Kind::Surface => self.material.map_or(Rgb::ZERO, |m| m.emitted(self.ng, w)),
            _ => Rgb::ZERO,
        }
    }

    /// The BSDF's pdf of `wi` for outgoing `wo`; `None` for `wo` is the stored one.
    pub fn bsdf_pdf(&self, wo: Option<Vec3>, wi: Vec3) -> f32 {
        match (wo, &self.bsdf, self.material) {
            (None, Some(b), _) => b.pdf(wi),
            (Some(wo), _, Some(m)) => Bsdf::new(m, self.tint, self.ns, self.ng, wo).pdf(wi),
            _ => 0.0,
        }
    }
}

/// Unit direction from `a` to `b` and their squared distance (infinite with the environment).
pub(super) fn direction(a: &Vertex, b: &Vertex) -> (Vec3, f32) {
    match (a.kind, b.kind) {
        (_, Kind::Env) => (b.p, f32::INFINITY),
        (Kind::Env, _) => (-a.p, f32::INFINITY),
        _ => {
            let d = b.p - a.p;
            let d2 = d.length_squared();
            (d / d2.sqrt(), d2)
        }
    }
}

/// A solid-angle density at `from` of the direction to `to`, as a density of `to`: area
/// measure at a point (`cos / d²`), unchanged for the environment.
pub(super) fn to_area(pdf: f32, from: &Vertex, to: &Vertex) -> f32 {
    if to.kind == Kind::Env {
        return pdf;
    }
    let (w, d2) = direction(from, to);
    let cos = if to.on_surface() {
        to.ng.dot(w).abs()
    } else {
        1.0
    };
    let v = pdf * cos / d2;
    if v.is_finite() {
        v
    } else {
        0.0
    }
}

/// What the densities need besides the vertices.
pub(super) struct Densities<'s> {
    pub scene: &'s Scene,
    pub lights: &'s LightSampler,
    pub camera: &'s Camera,
    /// The scene's box, which plane sampling covers.
    pub bounds: Aabb,
}

impl Densities<'_> {
    /// Density with which `from` samples `to`, `from` having been reached from direction
    /// `wo` (`None`: the stored one).
    pub fn pdf(&self, from: &Vertex, wo: Option<Vec3>, to: &Vertex) -> f32 {
        match from.kind {
            Kind::Camera => to_area(self.camera.pdf_direction(direction(from, to).0), from, to),
            Kind::Surface => to_area(from.bsdf_pdf(wo, direction(from, to).0), from, to),
            Kind::Light | Kind::Env => self.pdf_light(from, to),
        }
    }

    /// Density with which a light subpath starting at light `from` (an emitter point, an
    /// emissive surface, a delta light or the environment) reaches `to` as its next vertex.
    pub fn pdf_light(&self, from: &Vertex, to: &Vertex) -> f32 {
        let (w, _) = direction(from, to);
        if from.kind == Kind::Env {
            // Plane sampling: uniform on the rectangle perpendicular to the travel direction.
            let area = plane_area(&self.bounds, w);
            let cos = if to.on_surface() {
                to.ng.dot(w).abs()
            } else {
                1.0
            };
            return if area > 0.0 { cos / area } else { 0.0 };
        }
        if let Some(light) = &from.delta_light {
            return to_area(light.pdf_emit_direction(w), from, to);
        }
        let two_sided = match from.kind {
            Kind::Light => from.two_sided,
            _ => from.material.is_some_and(|m| m.two_sided),
        };
        let cos = from.ng.dot(w);
        let pdf_dir = if two_sided {
            0.5 * cos.abs() * FRAC_1_PI
        } else {
            cos.max(0.0) * FRAC_1_PI
        };
        to_area(pdf_dir, from, to)
    }

    /// Density with which a light subpath starts at light `v` (seen from `to`, which only the
    /// environment's direction needs).
    pub fn pdf_light_origin(&self, v: &Vertex) -> f32 {
        match v.kind {
            Kind::Env => self.lights.pdf_env(self.scene, v.p),
            _ => self.lights.pdf_emitter_area(self.scene, v.prim),
        }
    }
}
