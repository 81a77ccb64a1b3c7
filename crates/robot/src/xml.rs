//! What the URDF and MJCF readers share: reading the file, places of
//! elements, numbers and vectors from attributes.

use std::path::Path;

use nalgebra::Vector3;
use roxmltree::{Document, Node};

use crate::error::{Place, Result, RobotError};

/// The text of `file`.
pub(crate) fn read(file: &Path) -> Result<String> {
    std::fs::read_to_string(file).map_err(|e| {
        let what = e.to_string();
        let what = match what.find(" (os error ") {
            Some(i) => what[..i].to_lowercase(),
            None => what,
        };
        RobotError::Io {
            file: file.to_owned(),
            what,
        }
    })
}

/// The parsed document, or the parser's error with its line.
pub(crate) fn parse<'a>(file: &Path, text: &'a str) -> Result<Document<'a>> {
    Document::parse(text).map_err(|e| RobotError::Xml {
        file: file.to_owned(),
        line: e.pos().row,
        message: e.to_string(),
    })
}

/// Where `node` is: file, line, `<tag name="…">`.
pub(crate) fn place(file: &Path, node: Node) -> Place {
    let line = node.document().text_pos_at(node.range().start).row;
    let element = match node.attribute("name") {
        Some(n) => format!("<{} name=\"{}\">", node.tag_name().name(), n),
        None => format!("<{}>", node.tag_name().name()),
    };
    Place::new(file, line, element)
}

/// The numbers of attribute `attr` of `node` (space-separated), exactly
/// `n` of them if `n` is given.
pub(crate) fn numbers(file: &Path, node: Node, attr: &str, n: Option<usize>) -> Result<Vec<f64>> {
    let Some(text) = node.attribute(attr) else {
        return Err(RobotError::Missing {
            place: place(file, node),
            what: format!("attribute {attr}"),
        });
    };
    let bad = |expected: String| RobotError::BadValue {
        place: place(file, node),
        attribute: attr.to_owned(),
        value: text.to_owned(),
        expected,
    };
    let what = match n {
        Some(1) => "a finite number".to_owned(),
        Some(k) => format!("{k} finite numbers"),
        None => "finite numbers".to_owned(),
    };
    let xs: Vec<f64> = text
        .split_whitespace()
        .map(|t| t.parse::<f64>().ok().filter(|x| x.is_finite()))
        .collect::<Option<Vec<f64>>>()
        .ok_or_else(|| bad(what.clone()))?;
    if n.is_some_and(|k| xs.len() != k) {
        return Err(bad(what));
    }
    Ok(xs)
}

/// Attribute `attr` as one number, `default` when absent.
pub(crate) fn number_or(file: &Path, node: Node, attr: &str, default: f64) -> Result<f64> {
    if node.attribute(attr).is_none() {
        return Ok(default);
    }
    Ok(numbers(file, node, attr, Some(1))?[0])
}

/// Attribute `attr` as one number, if present.
pub(crate) fn number_opt(file: &Path, node: Node, attr: &str) -> Result<Option<f64>> {
    if node.attribute(attr).is_none() {
        return Ok(None);
    }
    Ok(Some(numbers(file, node, attr, Some(1))?[0]))
}

/// Attribute `attr` as a 3-vector, `default` when absent.
pub(crate) fn vec3_or(
    file: &Path,
    node: Node,
    attr: &str,
    default: Vector3<f64>,
) -> Result<Vector3<f64>> {
    if node.attribute(attr).is_none() {
        return Ok(default);
    }
    let v = numbers(file, node, attr, Some(3))?;
    Ok(Vector3::new(v[0], v[1], v[2]))
}

/// The error for a value that must be positive (or non-negative).
pub(crate) fn require(ok: bool, file: &Path, node: Node, attr: &str, expected: &str) -> Result<()> {
    if ok {
        return Ok(());
    }
    Err(RobotError::BadValue {
        place: place(file, node),
        attribute: attr.to_owned(),
        value: node.attribute(attr).unwrap_or("").to_owned(),
        expected: expected.to_owned(),
    })
}
