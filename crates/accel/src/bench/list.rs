//! The structures a benchmark compares, from their specs as text.

use crate::spec::{AccelSpec, SpecError};

/// Why a list of structures cannot be compared. The messages start with the spec at fault.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ListError {
    /// A spec that does not parse.
    #[error("{text}: {source}")]
    Spec {
        /// The spec as given.
        text: String,
        /// Why it does not parse.
        #[source]
        source: SpecError,
    },
    /// A structure that reorders the triangles, where frames are compared triangle by
    /// triangle.
    #[error(
        "{0}: a structure that reorders the scene's triangles cannot be compared frame by frame"
    )]
    Reorders(String),
    /// The same structure twice.
    #[error("{0} is listed twice")]
    Twice(AccelSpec),
    /// Nothing to compare.
    #[error("no acceleration structure given")]
    Empty,
}

/// The structures `list` names, each once and at least one; with `fixed_order`, none that
/// reorders the scene's triangles ([`crate::AccelKind::permutes`]).
pub fn contenders(list: &[String], fixed_order: bool) -> Result<Vec<AccelSpec>, ListError> {
    let mut specs: Vec<AccelSpec> = Vec::new();
    for text in list {
        let spec: AccelSpec = text.parse().map_err(|source| ListError::Spec {
            text: text.clone(),
            source,
        })?;
        if fixed_order && spec.kind.permutes() {
            return Err(ListError::Reorders(text.clone()));
        }
        if specs.contains(&spec) {
            return Err(ListError::Twice(spec));
        }
        specs.push(spec);
    }
    if specs.is_empty() {
        return Err(ListError::Empty);
    }
    Ok(specs)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn list(items: &[&str]) -> Vec<String> {
        items.iter().map(|s| s.to_string()).collect()
    }

    #[test]
    fn lists_refuse_repeats_reordering_and_nothing() {
        assert_eq!(contenders(&list(&["bvh8", "qbvh"]), true).unwrap().len(), 2);
        assert!(contenders(&list(&["iosp0"]), false).is_ok());
        assert!(matches!(
            contenders(&list(&["iosp0"]), true),
            Err(ListError::Reorders(_))
        ));
        assert!(matches!(
            contenders(&list(&["bvh8", "bvh8"]), true),
            Err(ListError::Twice(_))
        ));
        assert!(matches!(contenders(&[], false), Err(ListError::Empty)));
        assert!(matches!(
            contenders(&list(&["kd"]), false),
            Err(ListError::Spec { .. })
        ));
    }
}
