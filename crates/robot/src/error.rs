//! Typed errors of the robot crate: each names the file, and where the
//! description has one, the line and element at fault.

use std::path::{Path, PathBuf};

use thiserror::Error;

/// Where in a description file something is: the file, the 1-based line,
/// the element (`<joint name="FL_KFE">`). Boxed, so that every error stays
/// small.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Place(Box<(PathBuf, u32, String)>);

impl Place {
    /// The place of `element` at `line` of `file`.
    pub fn new(file: impl Into<PathBuf>, line: u32, element: impl Into<String>) -> Self {
        Self(Box::new((file.into(), line, element.into())))
    }

    /// The file (as given).
    pub fn file(&self) -> &Path {
        &self.0.0
    }

    /// 1-based line of the element.
    pub fn line(&self) -> u32 {
        self.0.1
    }

    /// The element's tag and name, e.g. `<joint name="FL_KFE">`.
    pub fn element(&self) -> &str {
        &self.0.2
    }
}

impl std::fmt::Display for Place {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{}:{}: {}",
            self.file().display(),
            self.line(),
            self.element()
        )
    }
}

/// Why a robot description cannot be loaded or built.
#[derive(Clone, Debug, PartialEq, Error)]
pub enum RobotError {
    /// The file cannot be read.
    #[error("{}: cannot read: {what}", file.display())]
    Io {
        /// The file.
        file: PathBuf,
        /// The operating system's message.
        what: String,
    },
    /// The file is not well-formed XML.
    #[error("{}:{line}: not well-formed XML: {message}", file.display())]
    Xml {
        /// The file.
        file: PathBuf,
        /// 1-based line.
        line: u32,
        /// The parser's message.
        message: String,
    },
    /// An element fbd does not model (a prismatic joint, a mesh-only foot,
    /// …).
    #[error("{place}: unsupported: {what}")]
    Unsupported {
        /// The element.
        place: Place,
        /// What is unsupported and what to do instead.
        what: String,
    },
    /// A required attribute or child is missing.
    #[error("{place}: missing {what}")]
    Missing {
        /// The element.
        place: Place,
        /// The attribute or child element.
        what: String,
    },
    /// An attribute's value is not what it must be.
    #[error("{place}: attribute {attribute} = \"{value}\": {expected}")]
    BadValue {
        /// The element.
        place: Place,
        /// The attribute.
        attribute: String,
        /// Its value as written.
        value: String,
        /// What it must be.
        expected: String,
    },
    /// The links and joints do not form one tree (a closed loop, two roots,
    /// a joint naming an unknown link).
    #[error("{place}: {message}")]
    Tree {
        /// The element at fault.
        place: Place,
        /// What is wrong.
        message: String,
    },
    /// A name asked for (a contact point, a joint) is not in the
    /// description.
    #[error("{}: no {kind} named \"{name}\"{hint}", file.display())]
    UnknownName {
        /// The description file.
        file: PathBuf,
        /// What was looked for: "link, site or collision sphere", "joint", …
        kind: &'static str,
        /// The name asked for.
        name: String,
        /// ` (did you mean "…"?)` or a list of what there is, or empty.
        hint: String,
    },
    /// The description has no point that can touch the ground.
    #[error("{}: no contact points: {message}", file.display())]
    NoContacts {
        /// The description file.
        file: PathBuf,
        /// Why, and what to do.
        message: String,
    },
}

impl RobotError {
    /// The description file at fault.
    pub fn file(&self) -> &Path {
        match self {
            RobotError::Io { file, .. }
            | RobotError::Xml { file, .. }
            | RobotError::UnknownName { file, .. }
            | RobotError::NoContacts { file, .. } => file,
            RobotError::Unsupported { place, .. }
            | RobotError::Missing { place, .. }
            | RobotError::BadValue { place, .. }
            | RobotError::Tree { place, .. } => place.file(),
        }
    }
}

/// Result of the robot crate.
pub type Result<T> = std::result::Result<T, RobotError>;
