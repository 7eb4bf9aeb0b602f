//! Reading a Mitsuba scene file into a plain element tree: XML parsed with positions,
//! `<include>`s spliced in, `<default>`s and `-D` values substituted for `$name`, and the
//! 0.x dialect (camelCase parameter names, `<lookAt>`) renamed to the 2.x/3.x one, as
//! Mitsuba 3 upgrades old files when it reads them.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::error::{LineCol, SceneError};
use crate::files::FileAccess;

/// Deepest include nesting; deeper is taken to be a cycle.
const MAX_INCLUDE_DEPTH: usize = 16;

/// One element: its tag, attributes (substituted), children and where it was written.
#[derive(Clone, Debug)]
pub(super) struct Node {
    pub tag: String,
    pub attrs: Vec<(String, String)>,
    pub children: Vec<Node>,
    pub at: Pos,
}

/// A position in one of the scene's files, for error lines.
#[derive(Clone, Debug)]
pub(super) struct Pos {
    pub file: Arc<PathBuf>,
    pub at: LineCol,
}

impl Pos {
    /// An error at this position.
    pub fn error(&self, message: impl Into<String>) -> SceneError {
        SceneError::Scene {
            file: self.file.as_ref().clone(),
            at: Some(self.at),
            message: message.into(),
        }
    }

    /// A warning line at this position.
    pub fn warning(&self, message: impl std::fmt::Display) -> String {
        format!("{}:{}: {message}", self.file.display(), self.at)
    }
}

impl Node {
    pub fn attr(&self, name: &str) -> Option<&str> {
        self.attrs
            .iter()
            .find(|(k, _)| k == name)
            .map(|(_, v)| v.as_str())
    }

    /// The `type` attribute, or an error naming the element.
    pub fn plugin(&self) -> Result<&str, SceneError> {
        self.attr("type")
            .ok_or_else(|| self.at.error(format!("<{}> has no type", self.tag)))
    }

    /// The `name` attribute, or an error.
    pub fn name(&self) -> Result<&str, SceneError> {
        self.attr("name")
            .ok_or_else(|| self.at.error(format!("<{}> has no name", self.tag)))
    }

    /// The `value` attribute, or an error naming the parameter.
    pub fn value(&self) -> Result<&str, SceneError> {
        self.attr("value").ok_or_else(|| {
            let name = self.attr("name").unwrap_or("?");
            self.at
                .error(format!("<{} name=\"{name}\"> has no value", self.tag))
        })
    }
}

/// The scene file's root `<scene>` with includes spliced in and parameters substituted.
/// `defines` (from `render -D name=value`) win over the file's `<default>`s.
pub(super) fn read(
    path: &Path,
    access: &FileAccess,
    defines: &[(String, String)],
) -> Result<Node, SceneError> {
    let mut root = parse_file(path, access, 0)?;
    let mut params: HashMap<String, String> = HashMap::new();
    // Defaults first (document order, later ones do not override earlier ones), then -D.
    for d in root.children.iter().filter(|c| c.tag == "default") {
        let name = d.name()?.to_string();
        let value = d.value()?.to_string();
        params.entry(name).or_insert(value);
    }
    for (k, v) in defines {
        params.insert(k.clone(), v.clone());
    }
    root.children.retain(|c| c.tag != "default");
    substitute(&mut root, &params)?;
    let textures: HashMap<String, Node> = root
        .children
        .iter()
        .filter(|c| c.tag == "texture")
        .filter_map(|c| Some((c.attr("id")?.to_string(), c.clone())))
        .collect();
    inline_texture_refs(&mut root, &textures);
    Ok(root)
}

/// `<ref name="reflectance" id="wood"/>` to a declared `<texture id="wood">` becomes a copy of
/// the texture named `reflectance`, so that parameters read textures in one way.
fn inline_texture_refs(node: &mut Node, textures: &HashMap<String, Node>) {
    for c in &mut node.children {
        let target = (c.tag == "ref")
            .then(|| c.attr("id").and_then(|id| textures.get(id)))
            .flatten();
        match (target, c.attr("name")) {
            (Some(t), Some(name)) => {
                let mut copy = t.clone();
                copy.attrs.retain(|(k, _)| k != "id" && k != "name");
                copy.attrs.push(("name".into(), name.to_string()));
                copy.at = c.at.clone();
                *c = copy;
            }
            _ => inline_texture_refs(c, textures),
        }
    }
}

fn parse_file(path: &Path, access: &FileAccess, depth: usize) -> Result<Node, SceneError> {
    access.check(path)?;
    let text = std::fs::read_to_string(path)
        .map_err(|e| SceneError::file(path, format!("cannot open: {e}")))?;
    let file = Arc::new(path.to_path_buf());
    let doc = roxmltree::Document::parse(&text).map_err(|e| {
        let p = e.pos();
        SceneError::Scene {
            file: path.to_path_buf(),
            at: Some(LineCol {
                line: p.row as usize,
                col: p.col as usize,
            }),
            message: format!("malformed XML: {e}"),
        }
    })?;
    let root = doc.root_element();
    let mut node = convert(&doc, root, &file);
    if node.tag != "scene" {
        return Err(node
            .at
            .error(format!("the root element is <{}>, not <scene>", node.tag)));
    }
    let old = node
        .attr("version")
        .is_some_and(|v| v.trim_start().starts_with("0."));
    if old {
        upgrade(&mut node);
    }
    splice_includes(&mut node, path, access, depth)?;
    Ok(node)
}

fn convert(doc: &roxmltree::Document, e: roxmltree::Node, file: &Arc<PathBuf>) -> Node {
    let p = doc.text_pos_at(e.range().start);
    Node {
        tag: e.tag_name().name().to_string(),
        attrs: e
            .attributes()
            .map(|a| (a.name().to_string(), a.value().to_string()))
            .collect(),
        children: e
            .children()
            .filter(|c| c.is_element())
            .map(|c| convert(doc, c, file))
            .collect(),
        at: Pos {
            file: file.clone(),
            at: LineCol {
                line: p.row as usize,
                col: p.col as usize,
            },
        },
    }
}

fn splice_includes(
    node: &mut Node,
    path: &Path,
    access: &FileAccess,
    depth: usize,
) -> Result<(), SceneError> {
    let mut out = Vec::with_capacity(node.children.len());
    for mut c in std::mem::take(&mut node.children) {
        if c.tag != "include" {
            splice_includes(&mut c, path, access, depth)?;
            out.push(c);
            continue;
        }
        if depth >= MAX_INCLUDE_DEPTH {
            return Err(c.at.error(format!(
                "includes nested deeper than {MAX_INCLUDE_DEPTH} (a cycle?)"
            )));
        }
        let name = c
            .attr("filename")
            .ok_or_else(|| c.at.error("<include> has no filename"))?;
        let target = path.parent().unwrap_or(Path::new("")).join(name);
        let included = parse_file(&target, access, depth + 1)?;
        out.extend(included.children);
    }
    node.children = out;
    Ok(())
}

/// The 0.x dialect as Mitsuba 3 upgrades it: camelCase parameter names become snake_case,
/// `<lookAt>` becomes `<lookat>`.
fn upgrade(node: &mut Node) {
    if node.tag == "lookAt" {
        node.tag = "lookat".into();
    }
    for (k, v) in &mut node.attrs {
        if k == "name" {
            *v = snake_case(v);
        }
    }
    for c in &mut node.children {
        upgrade(c);
    }
}

/// `intIOR` → `int_ior`, `maxDepth` → `max_depth`: an underscore before each capital that
/// follows a lower-case letter, then everything lower case.
pub(super) fn snake_case(s: &str) -> String {
    let mut out = String::with_capacity(s.len() + 4);
    let mut prev_lower = false;
    for ch in s.chars() {
        if ch.is_ascii_uppercase() && prev_lower {
            out.push('_');
        }
        prev_lower = ch.is_ascii_lowercase() || ch.is_ascii_digit();
        out.push(ch.to_ascii_lowercase());
    }
    out
}

fn substitute(node: &mut Node, params: &HashMap<String, String>) -> Result<(), SceneError> {
    for (_, v) in &mut node.attrs {
        if !v.contains('$') {
            continue;
        }
        let mut out = String::with_capacity(v.len());
        let mut rest = v.as_str();
        while let Some(i) = rest.find('$') {
            out.push_str(&rest[..i]);
            let tail = &rest[i + 1..];
            let len = tail
                .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
                .unwrap_or(tail.len());
            let name = &tail[..len];
            let Some(value) = params.get(name) else {
                return Err(node.at.error(format!(
                    "${name} has no value: give it with `-D {name}=VALUE` or a <default name=\"{name}\" value=\"...\"/>"
                )));
            };
            out.push_str(value);
            rest = &tail[len..];
        }
        out.push_str(rest);
        *v = out;
    }
    for c in &mut node.children {
        substitute(c, params)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn camel_case_names_become_snake_case_as_mitsuba_upgrades_them() {
        for (old, new) in [
            ("intIOR", "int_ior"),
            ("maxDepth", "max_depth"),
            ("toWorld", "to_world"),
            ("sampleCount", "sample_count"),
            ("diffuseReflectance", "diffuse_reflectance"),
            ("alphaU", "alpha_u"),
            ("fov", "fov"),
            ("max_depth", "max_depth"),
        ] {
            assert_eq!(snake_case(old), new);
        }
    }
}
