//! The parameters of one plugin element (`<bsdf type="...">` and its children), read by
//! name and type. Every parameter must be read or explicitly ignored: [`Props::finish`] turns
//! the ones nobody asked for into one error line, so an unsupported parameter never changes
//! the image silently.

use std::cell::RefCell;

use glam::{DMat4, DVec3};

use super::spectrum::{self, Role};
use super::xml::Node;
use crate::error::SceneError;

/// Tags that hold a nested plugin rather than a value.
const OBJECT_TAGS: [&str; 11] = [
    "bsdf",
    "emitter",
    "shape",
    "sensor",
    "film",
    "rfilter",
    "sampler",
    "integrator",
    "texture",
    "medium",
    "phase",
];

/// A colour parameter: a constant or a texture element.
#[derive(Debug, Clone)]
pub(super) enum Color<'a> {
    Rgb([f64; 3]),
    Texture(&'a Node),
}

/// The parameters and nested objects of one plugin element.
pub(super) struct Props<'a> {
    pub node: &'a Node,
    read: RefCell<Vec<bool>>,
    warnings: RefCell<Vec<String>>,
}

impl<'a> Props<'a> {
    pub fn new(node: &'a Node) -> Self {
        Self {
            node,
            read: RefCell::new(vec![false; node.children.len()]),
            warnings: RefCell::new(Vec::new()),
        }
    }

    /// What the element is, for messages: `bsdf "roughplastic"`.
    pub fn what(&self) -> String {
        format!(
            "{} \"{}\"",
            self.node.tag,
            self.node.attr("type").unwrap_or("?")
        )
    }

    /// An error at the element.
    pub fn error(&self, message: impl std::fmt::Display) -> SceneError {
        self.node.at.error(format!("{}: {message}", self.what()))
    }

    fn find(&self, name: &str) -> Option<(usize, &'a Node)> {
        let node = self.node;
        node.children
            .iter()
            .enumerate()
            .find(|(_, c)| c.attr("name") == Some(name) && c.tag != "ref")
            .inspect(|(i, _)| self.read.borrow_mut()[*i] = true)
    }

    /// The parameter `name` written with one of `tags`, or an error if it has another type.
    fn typed(&self, name: &str, tags: &[&str]) -> Result<Option<&'a Node>, SceneError> {
        let Some((_, c)) = self.find(name) else {
            return Ok(None);
        };
        if !tags.contains(&c.tag.as_str()) {
            return Err(c.at.error(format!(
                "{}: parameter `{name}` is a <{}>, expected <{}>",
                self.what(),
                c.tag,
                tags.join("> or <")
            )));
        }
        Ok(Some(c))
    }

    pub fn float(&self, name: &str) -> Result<Option<f64>, SceneError> {
        let Some(c) = self.typed(name, &["float", "integer"])? else {
            return Ok(None);
        };
        let v = number(c, c.value()?)?;
        Ok(Some(v))
    }

    pub fn integer(&self, name: &str) -> Result<Option<i64>, SceneError> {
        let Some(c) = self.typed(name, &["integer"])? else {
            return Ok(None);
        };
        let text = c.value()?.trim();
        text.parse::<i64>()
            .map(Some)
            .map_err(|_| c.at.error(format!("`{name}`: `{text}` is not an integer")))
    }

    pub fn boolean(&self, name: &str) -> Result<Option<bool>, SceneError> {
        let Some(c) = self.typed(name, &["boolean"])? else {
            return Ok(None);
        };
        match c.value()?.trim() {
            "true" => Ok(Some(true)),
            "false" => Ok(Some(false)),
            other => Err(c
                .at
                .error(format!("`{name}`: `{other}` is not true or false"))),
        }
    }

    pub fn string(&self, name: &str) -> Result<Option<&'a str>, SceneError> {
        let Some(c) = self.typed(name, &["string"])? else {
            return Ok(None);
        };
        c.value().map(Some)
    }

    /// A `<point>` or `<vector>`: `x`, `y`, `z` attributes or `value="x, y, z"`.
    pub fn point(&self, name: &str) -> Result<Option<DVec3>, SceneError> {
        let Some(c) = self.typed(name, &["point", "vector"])? else {
            return Ok(None);
        };
        xyz(c, 0.0).map(Some)
    }

    /// A colour parameter (`rgb`, `srgb`, `spectrum`, `float` or a `texture`) in `role`.
    pub fn color(&self, name: &str, role: Role) -> Result<Option<Color<'a>>, SceneError> {
        let Some(c) = self.typed(name, &["rgb", "srgb", "spectrum", "float", "texture"])? else {
            return Ok(None);
        };
        if c.tag == "texture" {
            return Ok(Some(Color::Texture(c)));
        }
        let (rgb, clamped) = color_value(c, role)?;
        if clamped {
            self.warn(
                c,
                format!("`{name}`: out-of-gamut colour clamped to {rgb:?}"),
            );
        }
        Ok(Some(Color::Rgb(rgb)))
    }

    /// A colour that must be constant (no texture).
    pub fn rgb(&self, name: &str, role: Role) -> Result<Option<[f64; 3]>, SceneError> {
        match self.color(name, role)? {
            None => Ok(None),
            Some(Color::Rgb(c)) => Ok(Some(c)),
            Some(Color::Texture(t)) => Err(t.at.error(format!(
                "{}: a texture on `{name}` is not supported (a constant colour is)",
                self.what()
            ))),
        }
    }

    pub fn transform(&self, name: &str) -> Result<Option<DMat4>, SceneError> {
        let Some(c) = self.typed(name, &["transform"])? else {
            return Ok(None);
        };
        transform(c).map(Some)
    }

    /// The nested plugin elements with tag `tag`, each marked read (references: [`Props::refs`]).
    pub fn objects(&self, tag: &str) -> Vec<&'a Node> {
        let node = self.node;
        let mut out = Vec::new();
        for (i, c) in node.children.iter().enumerate() {
            if c.tag == tag {
                self.read.borrow_mut()[i] = true;
                out.push(c);
            }
        }
        out
    }

    /// The `<ref id="...">` children, each marked read.
    pub fn refs(&self) -> Vec<&'a Node> {
        let node = self.node;
        let mut out = Vec::new();
        for (i, c) in node.children.iter().enumerate() {
            if c.tag == "ref" {
                self.read.borrow_mut()[i] = true;
                out.push(c);
            }
        }
        out
    }

    /// Parameter `name` when it is a texture: a nested `<texture name="...">` or a
    /// `<ref name="..." id="...">` to one (resolved by `resolve`), marked read; `None` when the
    /// parameter is absent or a constant.
    pub fn named_texture(
        &self,
        name: &str,
        resolve: &dyn Fn(&'a Node) -> Result<&'a Node, SceneError>,
    ) -> Result<Option<&'a Node>, SceneError> {
        let node = self.node;
        let Some((i, c)) = node.children.iter().enumerate().find(|(_, c)| {
            c.attr("name") == Some(name) && matches!(c.tag.as_str(), "texture" | "ref")
        }) else {
            return Ok(None);
        };
        self.read.borrow_mut()[i] = true;
        let t = if c.tag == "ref" { resolve(c)? } else { c };
        if t.tag != "texture" {
            return Err(c.at.error(format!(
                "{}: `{name}` refers to a <{}>, expected a <texture>",
                self.what(),
                t.tag
            )));
        }
        Ok(Some(t))
    }

    /// Accepts parameter `name` without using it, with a warning saying why.
    pub fn ignore(&self, name: &str, why: &str) {
        if let Some((_, c)) = self.find(name) {
            self.warn(c, format!("{}: `{name}` ignored: {why}", self.what()));
        }
    }

    /// Accepts parameter `name` silently: it cannot change the image.
    pub fn accept(&self, name: &str) {
        let _ = self.find(name);
    }

    fn warn(&self, c: &Node, message: String) {
        self.warnings.borrow_mut().push(c.at.warning(message));
    }

    /// The warnings gathered, or an error for the first parameter or object nobody read.
    pub fn finish(self, warnings: &mut Vec<String>) -> Result<(), SceneError> {
        let read = self.read.borrow();
        for (c, &r) in self.node.children.iter().zip(read.iter()) {
            if r {
                continue;
            }
            let message = if OBJECT_TAGS.contains(&c.tag.as_str()) {
                format!(
                    "{}: a nested <{} type=\"{}\"> is not supported here",
                    self.what(),
                    c.tag,
                    c.attr("type").unwrap_or("?")
                )
            } else {
                format!(
                    "{}: parameter `{}` is not supported",
                    self.what(),
                    c.attr("name").unwrap_or(&c.tag)
                )
            };
            return Err(c.at.error(message));
        }
        warnings.append(&mut self.warnings.borrow_mut());
        Ok(())
    }
}

/// The numbers of a list written with commas and/or spaces.
fn numbers(n: &Node, text: &str) -> Result<Vec<f64>, SceneError> {
    text.split(|c: char| c == ',' || c.is_whitespace())
        .filter(|s| !s.is_empty())
        .map(|s| {
            s.parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| n.at.error(format!("`{s}` is not a finite number")))
        })
        .collect()
}

fn number(n: &Node, text: &str) -> Result<f64, SceneError> {
    match numbers(n, text)?.as_slice() {
        [v] => Ok(*v),
        _ => Err(n.at.error(format!("`{}` is not one number", text.trim()))),
    }
}

/// `x`, `y`, `z` attributes (each defaulting to `default`) or `value="x, y, z"`.
fn xyz(n: &Node, default: f64) -> Result<DVec3, SceneError> {
    if let Some(v) = n.attr("value") {
        return match numbers(n, v)?.as_slice() {
            [x, y, z] => Ok(DVec3::new(*x, *y, *z)),
            [s] => Ok(DVec3::splat(*s)),
            _ => Err(n
                .at
                .error(format!("<{}>: `{v}` is not 1 or 3 numbers", n.tag))),
        };
    }
    let get = |k: &str| n.attr(k).map_or(Ok(default), |t| number(n, t));
    Ok(DVec3::new(get("x")?, get("y")?, get("z")?))
}

fn color_value(c: &Node, role: Role) -> Result<([f64; 3], bool), SceneError> {
    let text = c.value()?;
    match c.tag.as_str() {
        "float" => Ok((spectrum::uniform(number(c, text)?, role), false)),
        "rgb" => match numbers(c, text)?.as_slice() {
            [r, g, b] => Ok(([*r, *g, *b], false)),
            [v] => Ok(([*v; 3], false)),
            _ => Err(c.at.error(format!("<rgb>: `{text}` is not 3 numbers"))),
        },
        "srgb" => {
            let t = text.trim();
            let v = if let Some(hex) = t.strip_prefix('#') {
                let ok = hex.len() == 6 && hex.chars().all(|h| h.is_ascii_hexdigit());
                if !ok {
                    return Err(c.at.error(format!("<srgb>: `{t}` is not #rrggbb")));
                }
                [0, 2, 4]
                    .map(|i| u8::from_str_radix(&hex[i..i + 2], 16).unwrap_or(0) as f64 / 255.0)
            } else {
                match numbers(c, t)?.as_slice() {
                    [r, g, b] => [*r, *g, *b],
                    _ => return Err(c.at.error(format!("<srgb>: `{t}` is not 3 numbers"))),
                }
            };
            Ok((v.map(spectrum::srgb_to_linear), false))
        }
        _ => spectrum_value(c, text, role),
    }
}

/// `<spectrum value="0.5">` or `value="400:0.1, 500:0.3, ..."`.
fn spectrum_value(c: &Node, text: &str, role: Role) -> Result<([f64; 3], bool), SceneError> {
    if c.attr("filename").is_some() {
        return Err(c
            .at
            .error("<spectrum filename=...>: spectra from files are not supported"));
    }
    if !text.contains(':') {
        return Ok((spectrum::uniform(number(c, text)?, role), false));
    }
    let mut w = Vec::new();
    let mut v = Vec::new();
    for pair in text.split(',').map(str::trim).filter(|p| !p.is_empty()) {
        let parsed = pair.split_once(':').and_then(|(a, b)| {
            Some((a.trim().parse::<f64>().ok()?, b.trim().parse::<f64>().ok()?))
        });
        let Some((wl, val)) = parsed.filter(|(a, b)| a.is_finite() && b.is_finite()) else {
            return Err(c
                .at
                .error(format!("<spectrum>: `{pair}` is not wavelength:value")));
        };
        if w.last().is_some_and(|&last| wl <= last) {
            return Err(c.at.error("<spectrum>: wavelengths must increase"));
        }
        w.push(wl);
        v.push(val);
    }
    if w.len() < 2 {
        return Err(c
            .at
            .error("<spectrum>: needs at least two wavelength:value pairs"));
    }
    Ok(spectrum::to_rgb(&w, &v, role))
}

/// A `<transform>`: its operations applied in order (each later one after the earlier).
pub(super) fn transform(t: &Node) -> Result<DMat4, SceneError> {
    let mut m = DMat4::IDENTITY;
    for op in &t.children {
        let step = match op.tag.as_str() {
            "translate" => DMat4::from_translation(xyz(op, 0.0)?),
            "scale" => DMat4::from_scale(xyz(op, 1.0)?),
            "rotate" => {
                let axis = xyz(op, 0.0)?;
                let angle = op
                    .attr("angle")
                    .ok_or_else(|| op.at.error("<rotate> has no angle"))?;
                let angle = number(op, angle)?;
                if axis.length_squared() == 0.0 {
                    return Err(op.at.error("<rotate>: the axis is zero"));
                }
                DMat4::from_axis_angle(axis.normalize(), angle.to_radians())
            }
            "matrix" => {
                let v = numbers(op, op.value()?)?;
                match v.len() {
                    16 => DMat4::from_cols_array(&[
                        v[0], v[4], v[8], v[12], v[1], v[5], v[9], v[13], v[2], v[6], v[10], v[14],
                        v[3], v[7], v[11], v[15],
                    ]),
                    9 => DMat4::from_cols_array(&[
                        v[0], v[3], v[6], 0.0, v[1], v[4], v[7], 0.0, v[2], v[5], v[8], 0.0, 0.0,
                        0.0, 0.0, 1.0,
                    ]),
                    n => {
                        return Err(op
                            .at
                            .error(format!("<matrix>: {n} numbers, expected 16 or 9")))
                    }
                }
            }
            "lookat" => look_at(op)?,
            other => {
                return Err(op
                    .at
                    .error(format!("<transform>: <{other}> is not supported")))
            }
        };
        m = step * m;
    }
    Ok(m)
}

/// Mitsuba's `lookat`: columns left, up, direction and origin (+z looks at the target).
fn look_at(op: &Node) -> Result<DMat4, SceneError> {
    let get = |k: &str| -> Result<DVec3, SceneError> {
        let text = op
            .attr(k)
            .ok_or_else(|| op.at.error(format!("<lookat> has no {k}")))?;
        match numbers(op, text)?.as_slice() {
            [x, y, z] => Ok(DVec3::new(*x, *y, *z)),
            _ => Err(op
                .at
                .error(format!("<lookat>: {k} `{text}` is not 3 numbers"))),
        }
    };
    let origin = get("origin")?;
    let target = get("target")?;
    let up = if op.attr("up").is_some() {
        get("up")?
    } else {
        DVec3::Y
    };
    let dir = (target - origin).normalize_or_zero();
    let left = up.normalize_or_zero().cross(dir);
    if dir == DVec3::ZERO || left.length_squared() < 1e-20 {
        return Err(op
            .at
            .error("<lookat>: origin equals target, or up is parallel to the view direction"));
    }
    let left = left.normalize();
    let new_up = dir.cross(left);
    Ok(DMat4::from_cols(
        left.extend(0.0),
        new_up.extend(0.0),
        dir.extend(0.0),
        origin.extend(1.0),
    ))
}
