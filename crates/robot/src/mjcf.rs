//! MJCF (MuJoCo XML) robot descriptions, into a [`RawTree`], with
//! MuJoCo's documented semantics:
//!
//! * `<compiler>`: `angle` (`degree`, MJCF's default, or `radian`: joint
//!   `range` and `ref`, `euler` and `axisangle` angles), `eulerseq`
//!   (default `xyz`; lowercase letters turn about the rotating axes,
//!   uppercase about the fixed ones), `autolimits` (default `true`: a
//!   `range` makes a joint limited), `inertiafromgeom` (`auto`, `true`,
//!   `false`) and `inertiagrouprange`;
//! * `<default>` classes, nested (the top-level one is `main`), for
//!   `joint`, `geom`, `site` and the actuators; an element's `class`, else
//!   the nearest `childclass` of its bodies, else `main`;
//! * orientations: `quat` (`w x y z`), `euler`, `axisangle`, `xyaxes`,
//!   `zaxis` (the shortest turn from `+z`);
//! * `<worldbody>` holds exactly one `<body>`, the robot's root (the
//!   floating base, with a `<freejoint/>` or no joint; its own `pos` and
//!   orientation are ignored: the user places the base); worldbody geoms,
//!   sites, lights and cameras are scenery and ignored;
//! * a child body with no joint is welded to its parent; one with `k`
//!   hinges is reached through `k` revolute joints composed as MuJoCo
//!   does, `T = T_body·[Tr(p1)·R1·Tr(−p1)]·…·[Tr(pk)·Rk·Tr(−pk)]`, each
//!   about its own axis through its own `pos` (body coordinates): hinges
//!   `1..k−1` end in massless links `{body}/{joint}` whose frames are the
//!   body's frame moved to the hinge's `pos`, the last in the body's own
//!   link, whose frame is the body's frame moved to `pk` (every content of
//!   the body is shifted by `−pk`). A hinge's `ref` turns its origin by
//!   `−ref` (MuJoCo's angle is `qpos − ref` from the written pose);
//! * `<inertial>` (`diaginertia` or `fullinertia`, order
//!   `ixx iyy izz ixy ixz iyz`), or the mass of the body's geoms (sphere,
//!   capsule, cylinder, box, ellipsoid; `mass`, else `density` × volume,
//!   default density 1000) combined about their common centre of mass;
//! * sphere geoms that collide (`contype` or `conaffinity` nonzero) are
//!   collision spheres; other colliding geoms are kept only to say where a
//!   mesh-only foot is; sites are named points;
//! * `<actuator>`: `motor`, `position`, `velocity`, `intvelocity`,
//!   `general` and `damper` on a joint; the effort limit is
//!   `max|forcerange|·|gear[0]|` when the force is limited;
//! * slide, ball and free (on a child body) joints, hinges on the root
//!   (a fixed-base robot), `<include>`, `<frame>`, `<replicate>`,
//!   `<attach>`, `<composite>`, `<flexcomp>`, equality constraints, mesh
//!   geoms needed for a mass, tendon/site/body transmissions and other
//!   actuator kinds are errors naming the file, line and element;
//!   `<option>`, `<size>`, `<visual>`, `<asset>`, `<contact>`, `<tendon>`,
//!   `<sensor>`, `<keyframe>`, joint damping, stiffness and armature are
//!   ignored.

use std::collections::HashMap;
use std::path::Path;

use nalgebra::{Isometry3, Matrix3, Quaternion, Rotation3, Translation3, UnitQuaternion, Vector3};
use roxmltree::Node;

use crate::error::{Place, Result, RobotError};
use crate::model::{JointLimits, RobotModel};
use crate::tree::{
    ContactChoice, RawActuator, RawInertial, RawJoint, RawJointKind, RawLink, RawPoint, RawTree, Up,
};
use crate::xml::{self, place};

/// Reads and builds the model of MJCF `file`:
/// `parse(file, read(file)?)?.build(up, contacts)`.
pub fn load(file: &Path, up: Up, contacts: &ContactChoice) -> Result<RobotModel> {
    let text = xml::read(file)?;
    parse(file, &text)?.build(up, contacts)
}

/// The links, joints and actuators of an MJCF document as written (no
/// tree checks yet; `file` names it in messages).
pub fn parse(file: &Path, text: &str) -> Result<RawTree> {
    let doc = xml::parse(file, text)?;
    let root = doc.root_element();
    if root.tag_name().name() != "mujoco" {
        return Err(unsupported(
            place(file, root),
            "an MJCF's root element is <mujoco>".to_owned(),
        ));
    }
    refuse_unsupported(file, root)?;
    let compiler = Compiler::read(file, root)?;
    let classes = read_defaults(file, root)?;
    let mut reader = Reader {
        file,
        compiler,
        classes,
        links: Vec::new(),
        joints: Vec::new(),
        bodies: 0,
    };

    let worlds: Vec<Node> = root
        .children()
        .filter(|n| n.has_tag_name("worldbody"))
        .collect();
    let Some(&first_world) = worlds.first() else {
        return Err(missing(
            place(file, root),
            "<worldbody> (with the robot's root <body>)".to_owned(),
        ));
    };
    let bodies: Vec<Node> = worlds
        .iter()
        .flat_map(|w| w.children().filter(|n| n.has_tag_name("body")))
        .collect();
    let robot = match bodies[..] {
        [] => {
            return Err(missing(
                place(file, first_world),
                "a <body> in <worldbody> (the robot's root)".to_owned(),
            ));
        }
        [b] => b,
        [a, b, ..] => {
            return Err(tree_error(
                place(file, b),
                format!(
                    "a second body \"{}\" in <worldbody> besides \"{}\": fbd models one robot, \
                     one tree under one root body (scenery belongs in worldbody geoms)",
                    b.attribute("name").unwrap_or("(unnamed)"),
                    a.attribute("name").unwrap_or("(unnamed)")
                ),
            ));
        }
    };
    let world_class = first_world.attribute("childclass").unwrap_or("main");
    let world_class = reader.class_name(first_world, "childclass", world_class)?;
    reader.body(robot, None, &world_class)?;
    let actuators = reader.actuators(root)?;

    let name = root
        .attribute("model")
        .map(str::to_owned)
        .or_else(|| file.file_stem().map(|s| s.to_string_lossy().into_owned()))
        .unwrap_or_else(|| "mujoco".to_owned());
    Ok(RawTree {
        file: file.to_owned(),
        name,
        links: reader.links,
        joints: reader.joints,
        actuators,
    })
}

/// Elements fbd cannot read anywhere in the file.
fn refuse_unsupported(file: &Path, root: Node) -> Result<()> {
    for node in root.descendants().filter(Node::is_element) {
        let what = match node.tag_name().name() {
            "include" => {
                "<include>: fbd reads one self-contained file; paste the included file's \
                 contents in its place"
            }
            _ => continue,
        };
        return Err(unsupported(place(file, node), what.to_owned()));
    }
    for world in root.children().filter(|n| n.has_tag_name("worldbody")) {
        for node in world.descendants().filter(Node::is_element) {
            let what = match node.tag_name().name() {
                "frame" => {
                    "<frame>: fbd does not read frames; move its children into the enclosing \
                     body with their poses composed"
                }
                "replicate" => "<replicate>: write the repeated bodies out",
                "attach" => "<attach>: fbd reads one self-contained model",
                "composite" | "flexcomp" => "composite and flexible objects",
                _ => continue,
            };
            return Err(unsupported(place(file, node), what.to_owned()));
        }
    }
    for equality in root.children().filter(|n| n.has_tag_name("equality")) {
        if let Some(node) = equality.children().find(Node::is_element) {
            return Err(unsupported(
                place(file, node),
                "an equality constraint (a closed loop or coupled joints): fbd models \
                       open trees of independent revolute joints"
                    .to_owned(),
            ));
        }
    }
    Ok(())
}

/// Where `inertiafromgeom` takes mass properties from geoms.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum FromGeom {
    /// When the body has no `<inertial>`.
    Auto,
    /// Always (the geoms override `<inertial>`).
    Always,
    /// Never.
    Never,
}

/// The `<compiler>` settings that change what a description means.
#[derive(Clone, Debug)]
struct Compiler {
    /// Angles in degrees (MJCF's default) rather than radians.
    degree: bool,
    /// The Euler sequence, e.g. `b"xyz"`.
    eulerseq: [u8; 3],
    /// A `range` makes a joint (a `forcerange` an actuator) limited.
    autolimits: bool,
    /// Mass properties from geoms.
    from_geom: FromGeom,
    /// The geom groups whose geoms give mass properties.
    group_range: [f64; 2],
}

impl Compiler {
    /// The settings of every `<compiler>` of `root`, in order.
    fn read(file: &Path, root: Node) -> Result<Self> {
        let mut c = Compiler {
            degree: true,
            eulerseq: *b"xyz",
            autolimits: true,
            from_geom: FromGeom::Auto,
            group_range: [0.0, 5.0],
        };
        for node in root.children().filter(|n| n.has_tag_name("compiler")) {
            let el = El::plain(node);
            if node.has_attribute("angle") {
                c.degree = el.choice(file, "angle", &["degree", "radian"], "degree")? == "degree";
            }
            if let Some(seq) = node.attribute("eulerseq") {
                let ok = seq.len() == 3 && seq.bytes().all(|b| b"xyzXYZ".contains(&b));
                xml::require(
                    ok,
                    file,
                    node,
                    "eulerseq",
                    "three of the letters x, y, z, X, Y, Z",
                )?;
                c.eulerseq.copy_from_slice(seq.as_bytes());
            }
            if node.has_attribute("autolimits") {
                c.autolimits = el.choice(file, "autolimits", &["true", "false"], "true")? == "true";
            }
            if node.has_attribute("inertiafromgeom") {
                c.from_geom =
                    match el.choice(file, "inertiafromgeom", &["auto", "true", "false"], "auto")? {
                        "true" => FromGeom::Always,
                        "false" => FromGeom::Never,
                        _ => FromGeom::Auto,
                    };
            }
            if node.has_attribute("inertiagrouprange") {
                let r = xml::numbers(file, node, "inertiagrouprange", Some(2))?;
                c.group_range = [r[0], r[1]];
            }
            if node.attribute("coordinate") == Some("global") {
                return Err(unsupported(
                    place(file, node),
                    "coordinate=\"global\" (removed from MuJoCo): write local \
                           coordinates"
                        .to_owned(),
                ));
            }
            for attr in ["boundmass", "boundinertia", "settotalmass"] {
                if xml::number_or(file, node, attr, 0.0)? > 0.0 {
                    return Err(unsupported(
                        place(file, node),
                        format!(
                            "compiler {attr}: fbd takes masses and inertias as written; \
                             write the intended values into the bodies"
                        ),
                    ));
                }
            }
        }
        Ok(c)
    }

    /// `x` (degrees or radians as the compiler says) in radians.
    fn angle(&self, x: f64) -> f64 {
        if self.degree { x.to_radians() } else { x }
    }
}

/// Attribute defaults of one element kind: attribute → the default
/// element that writes it.
type Attrs<'a, 'i> = HashMap<String, Node<'a, 'i>>;

/// The defaults of one `<default>` class (its parents' included).
#[derive(Clone, Debug, Default)]
struct Class<'a, 'i> {
    /// `<joint>` defaults.
    joint: Attrs<'a, 'i>,
    /// `<geom>` defaults.
    geom: Attrs<'a, 'i>,
    /// `<site>` defaults.
    site: Attrs<'a, 'i>,
    /// Actuator defaults (MuJoCo keeps one per class for every kind).
    actuator: Attrs<'a, 'i>,
}

/// The actuator elements (in `<actuator>` and `<default>`).
const ACTUATOR_TAGS: [&str; 12] = [
    "general",
    "motor",
    "position",
    "velocity",
    "damper",
    "intvelocity",
    "orientation",
    "pid",
    "cylinder",
    "muscle",
    "adhesion",
    "dcmotor",
];

impl<'a, 'i> Class<'a, 'i> {
    /// Adds the defaults written in `<default>` element `node` (not its
    /// nested classes).
    fn fill(&mut self, node: Node<'a, 'i>) {
        for child in node.children().filter(Node::is_element) {
            let tag = child.tag_name().name();
            let attrs = match tag {
                "joint" => &mut self.joint,
                "geom" => &mut self.geom,
                "site" => &mut self.site,
                _ if ACTUATOR_TAGS.contains(&tag) => &mut self.actuator,
                _ => continue,
            };
            for a in child.attributes() {
                attrs.insert(a.name().to_owned(), child);
            }
        }
    }
}

/// Every `<default>` class of the file by name (`main` always).
fn read_defaults<'a, 'i>(
    file: &Path,
    root: Node<'a, 'i>,
) -> Result<HashMap<String, Class<'a, 'i>>> {
    let mut classes = HashMap::new();
    classes.insert("main".to_owned(), Class::default());
    for top in root.children().filter(|n| n.has_tag_name("default")) {
        if let Some(name) = top.attribute("class") {
            xml::require(
                name == "main",
                file,
                top,
                "class",
                "\"main\" or nothing: the top-level default class is main",
            )?;
        }
        let mut main = classes["main"].clone();
        main.fill(top);
        for nested in top.children().filter(|n| n.has_tag_name("default")) {
            nested_default(file, nested, &main, &mut classes)?;
        }
        classes.insert("main".to_owned(), main);
    }
    Ok(classes)
}

/// Reads nested `<default>` `node` (and its own nested classes) on top of
/// its parent class.
fn nested_default<'a, 'i>(
    file: &Path,
    node: Node<'a, 'i>,
    parent: &Class<'a, 'i>,
    classes: &mut HashMap<String, Class<'a, 'i>>,
) -> Result<()> {
    let Some(name) = node.attribute("class") else {
        return Err(missing(
            place(file, node),
            "attribute class (a nested <default> names its class)".to_owned(),
        ));
    };
    xml::require(
        name != "main" && !classes.contains_key(name),
        file,
        node,
        "class",
        "a class name not used before",
    )?;
    let mut class = parent.clone();
    class.fill(node);
    // Reserve the name before the nested classes (a nested class of the
    // same name is a repeat).
    classes.insert(name.to_owned(), Class::default());
    for nested in node.children().filter(|n| n.has_tag_name("default")) {
        nested_default(file, nested, &class, classes)?;
    }
    classes.insert(name.to_owned(), class);
    Ok(())
}

/// An element with the defaults of its class: its own attribute, else its
/// class's.
#[derive(Clone, Copy)]
struct El<'c, 'a, 'i> {
    /// The element.
    node: Node<'a, 'i>,
    /// Its class's defaults for its kind.
    defaults: Option<&'c Attrs<'a, 'i>>,
}

impl<'c, 'a, 'i> El<'c, 'a, 'i> {
    /// An element without defaults.
    fn plain(node: Node<'a, 'i>) -> Self {
        Self {
            node,
            defaults: None,
        }
    }

    /// The element that writes `attr`: this one, else its default.
    fn holder(&self, attr: &str) -> Option<Node<'a, 'i>> {
        if self.node.has_attribute(attr) {
            return Some(self.node);
        }
        self.defaults.and_then(|d| d.get(attr).copied())
    }

    /// Attribute `attr`'s text.
    fn text(&self, attr: &str) -> Option<&'a str> {
        self.holder(attr).and_then(|n| n.attribute(attr))
    }

    /// Attribute `attr`'s numbers (exactly `n` if given), if written.
    fn nums(&self, file: &Path, attr: &str, n: Option<usize>) -> Result<Option<Vec<f64>>> {
        match self.holder(attr) {
            None => Ok(None),
            Some(h) => xml::numbers(file, h, attr, n).map(Some),
        }
    }

    /// Attribute `attr` as one number, `default` when absent.
    fn num_or(&self, file: &Path, attr: &str, default: f64) -> Result<f64> {
        Ok(self.nums(file, attr, Some(1))?.map_or(default, |v| v[0]))
    }

    /// Attribute `attr` as a 3-vector, `default` when absent.
    fn vec3_or(&self, file: &Path, attr: &str, default: Vector3<f64>) -> Result<Vector3<f64>> {
        Ok(self
            .nums(file, attr, Some(3))?
            .map_or(default, |v| Vector3::new(v[0], v[1], v[2])))
    }

    /// Attribute `attr`, one of `options`, `default` when absent.
    fn choice(
        &self,
        file: &Path,
        attr: &str,
        options: &[&'static str],
        default: &'static str,
    ) -> Result<&'static str> {
        let Some(h) = self.holder(attr) else {
            return Ok(default);
        };
        let value = h.attribute(attr).unwrap_or_default();
        options
            .iter()
            .find(|o| **o == value)
            .copied()
            .ok_or_else(|| {
                bad_value(
                    place(file, h),
                    attr.to_owned(),
                    value.to_owned(),
                    format!("one of {}", options.join(", ")),
                )
            })
    }

    /// The error for attribute `attr` (at the element writing it).
    fn bad(&self, file: &Path, attr: &str, expected: impl Into<String>) -> RobotError {
        let node = self.holder(attr).unwrap_or(self.node);
        bad_value(
            place(file, node),
            attr.to_owned(),
            node.attribute(attr).unwrap_or_default().to_owned(),
            expected.into(),
        )
    }
}

/// The orientation alternatives to `quat`.
const ALTERNATIVES: [&str; 4] = ["axisangle", "xyaxes", "zaxis", "euler"];

/// Shortest rotation taking `+z` to `v` (MuJoCo's `z2quat`: half a turn
/// about `x` for `−z`).
fn z_to(v: &Vector3<f64>) -> UnitQuaternion<f64> {
    let v = v.normalize();
    let cross = Vector3::z().cross(&v);
    let s = cross.norm();
    let axis = if s < 1e-10 {
        Vector3::x_axis()
    } else {
        nalgebra::Unit::new_unchecked(cross / s)
    };
    UnitQuaternion::from_axis_angle(&axis, s.atan2(v.z))
}

/// One hinge of a body, as written.
struct Hinge {
    /// Its name.
    name: String,
    /// Where it is written.
    place: Place,
    /// Its point in body coordinates.
    pos: Vector3<f64>,
    /// Its axis in body coordinates.
    axis: Vector3<f64>,
    /// `ref` (rad).
    reference: f64,
    /// Position limits.
    limits: Option<JointLimits>,
    /// `max|actuatorfrcrange|`.
    effort: Option<f64>,
}

/// One geom of a body, resolved.
struct Geom {
    /// Its name, if written.
    name: Option<String>,
    /// Where it is written.
    place: Place,
    /// Its shape.
    kind: &'static str,
    /// Its size parameters (0 where not written).
    size: [f64; 3],
    /// Its frame in body coordinates.
    frame: Isometry3<f64>,
    /// `contype` or `conaffinity` nonzero.
    collides: bool,
    /// `group`.
    group: f64,
    /// `mass`, if written.
    mass: Option<f64>,
    /// `density`.
    density: f64,
    /// `shellinertia="true"`.
    shell: bool,
    /// Its shape comes from a mesh (a mesh geom or one fitted to a mesh).
    from_mesh: bool,
}

/// Walks the bodies, collecting links and joints.
struct Reader<'f, 'a, 'i> {
    /// The file (for messages).
    file: &'f Path,
    /// Compiler settings.
    compiler: Compiler,
    /// Default classes.
    classes: HashMap<String, Class<'a, 'i>>,
    /// Links so far.
    links: Vec<RawLink>,
    /// Joints so far.
    joints: Vec<RawJoint>,
    /// Bodies so far (MuJoCo's body id of the last one).
    bodies: usize,
}

impl<'a, 'i> Reader<'_, 'a, 'i> {
    /// Class `default` (a `class` or `childclass` value), checked.
    fn class_name(&self, node: Node, attr: &str, name: &str) -> Result<String> {
        if self.classes.contains_key(name) {
            return Ok(name.to_owned());
        }
        let known: Vec<&str> = self.classes.keys().map(String::as_str).collect();
        Err(bad_value(
            place(self.file, node),
            attr.to_owned(),
            name.to_owned(),
            format!(
                "a <default class=...> of the file{}",
                crate::suggest(name, &known)
            ),
        ))
    }

    /// The class of element `node`: its `class`, else `inherited`.
    fn class_of(&self, node: Node, inherited: &str) -> Result<&Class<'a, 'i>> {
        let name = match node.attribute("class") {
            Some(c) => self.class_name(node, "class", c)?,
            None => inherited.to_owned(),
        };
        Ok(&self.classes[&name])
    }

    /// The orientation of `el` (identity if none is written).
    fn orientation(&self, el: &El) -> Result<UnitQuaternion<f64>> {
        let file = self.file;
        let own: Vec<&str> = std::iter::once("quat")
            .chain(ALTERNATIVES)
            .filter(|a| el.node.has_attribute(*a))
            .collect();
        if let [first, second, ..] = own[..] {
            return Err(el.bad(
                file,
                second,
                format!("one orientation per element ({first} is given too)"),
            ));
        }
        // An alternative of the element, else of its class (MuJoCo keeps a
        // class's alternative over the element's own quat).
        let alt = ALTERNATIVES
            .into_iter()
            .find(|a| el.node.has_attribute(*a))
            .or_else(|| {
                ALTERNATIVES
                    .into_iter()
                    .find(|a| el.defaults.is_some_and(|d| d.contains_key(*a)))
            });
        let tiny = 1e-14;
        match alt {
            Some("axisangle") => {
                let v = el.nums(file, "axisangle", Some(4))?.unwrap_or_default();
                let axis = Vector3::new(v[0], v[1], v[2]);
                if axis.norm() < tiny {
                    return Err(el.bad(file, "axisangle", "a nonzero axis and an angle"));
                }
                Ok(UnitQuaternion::from_axis_angle(
                    &nalgebra::Unit::new_normalize(axis),
                    self.compiler.angle(v[3]),
                ))
            }
            Some("xyaxes") => {
                let v = el.nums(file, "xyaxes", Some(6))?.unwrap_or_default();
                let x = Vector3::new(v[0], v[1], v[2]);
                let y = Vector3::new(v[3], v[4], v[5]);
                if x.norm() < tiny {
                    return Err(el.bad(file, "xyaxes", "a nonzero x axis"));
                }
                let x = x.normalize();
                let y = y - x * x.dot(&y);
                if y.norm() < tiny {
                    return Err(el.bad(file, "xyaxes", "a y axis not along the x axis"));
                }
                let y = y.normalize();
                let z = x.cross(&y);
                let m = Matrix3::from_columns(&[x, y, z]);
                Ok(UnitQuaternion::from_rotation_matrix(
                    &Rotation3::from_matrix_unchecked(m),
                ))
            }
            Some("zaxis") => {
                let z = el.vec3_or(file, "zaxis", Vector3::z())?;
                if z.norm() < tiny {
                    return Err(el.bad(file, "zaxis", "a nonzero vector"));
                }
                Ok(z_to(&z))
            }
            Some(_) => {
                let v = el.nums(file, "euler", Some(3))?.unwrap_or_default();
                let mut q = UnitQuaternion::identity();
                for (k, &letter) in self.compiler.eulerseq.iter().enumerate() {
                    let axis = match letter.to_ascii_lowercase() {
                        b'x' => Vector3::x_axis(),
                        b'y' => Vector3::y_axis(),
                        _ => Vector3::z_axis(),
                    };
                    let turn = UnitQuaternion::from_axis_angle(&axis, self.compiler.angle(v[k]));
                    q = if letter.is_ascii_lowercase() {
                        q * turn
                    } else {
                        turn * q
                    };
                }
                Ok(q)
            }
            None => match el.nums(file, "quat", Some(4))? {
                None => Ok(UnitQuaternion::identity()),
                Some(v) => {
                    let q = Quaternion::new(v[0], v[1], v[2], v[3]);
                    if q.norm() < tiny {
                        return Err(el.bad(file, "quat", "a nonzero quaternion (w x y z)"));
                    }
                    Ok(UnitQuaternion::from_quaternion(q))
                }
            },
        }
    }

    /// `pos` and orientation of `el`.
    fn frame(&self, el: &El) -> Result<Isometry3<f64>> {
        let pos = el.vec3_or(self.file, "pos", Vector3::zeros())?;
        Ok(Isometry3::from_parts(
            Translation3::from(pos),
            self.orientation(el)?,
        ))
    }

    /// Reads `<body>` `node` and its subtree. `parent`: the parent body's
    /// link and the shift of its contents (`None` for the root);
    /// `inherited`: the class its elements default to.
    fn body(
        &mut self,
        node: Node<'a, 'i>,
        parent: Option<(&str, Vector3<f64>)>,
        inherited: &str,
    ) -> Result<()> {
        let file = self.file;
        self.bodies += 1;
        let name = node
            .attribute("name")
            .map(str::to_owned)
            .unwrap_or_else(|| format!("body{}", self.bodies));
        let class = match node.attribute("childclass") {
            Some(c) => self.class_name(node, "childclass", c)?,
            None => inherited.to_owned(),
        };
        let body_place = place(file, node);

        let mut inertial = None;
        let mut hinges: Vec<Hinge> = Vec::new();
        let mut geoms = Vec::new();
        let mut sites = Vec::new();
        let mut children = Vec::new();
        let mut free = 0;
        for child in node.children().filter(Node::is_element) {
            let tag = child.tag_name().name();
            match tag {
                "inertial" => {
                    if inertial.is_some() {
                        return Err(unsupported(
                            place(file, child),
                            "a second <inertial> in one body".to_owned(),
                        ));
                    }
                    inertial = Some(child);
                }
                "joint" | "freejoint" => {
                    let defaults = &self.class_of(child, &class)?.joint;
                    let el = El {
                        node: child,
                        defaults: Some(defaults),
                    };
                    let kind = if tag == "freejoint" {
                        "free"
                    } else {
                        el.choice(file, "type", &["hinge", "slide", "ball", "free"], "hinge")?
                    };
                    let unsupported = |what: String| Err(unsupported(place(file, child), what));
                    match (parent.is_some(), kind) {
                        (false, "free") => {
                            free += 1;
                            if free > 1 {
                                return unsupported(
                                    "a second free joint on the root body".to_owned(),
                                );
                            }
                        }
                        (false, _) => {
                            return unsupported(format!(
                                "a fixed-base robot: the root body \"{name}\" has a {kind} \
                                 joint to the world; fbd models floating-base robots (give \
                                 the root body a <freejoint/> or no joint)"
                            ));
                        }
                        (true, "hinge") => {
                            let k = hinges.len() + 1;
                            hinges.push(self.hinge(&el, &name, k)?);
                        }
                        (true, "slide") => {
                            return unsupported(
                                "a slide (prismatic) joint: fbd models revolute joints".to_owned(),
                            );
                        }
                        (true, "ball") => {
                            return unsupported(
                                "a ball joint: fbd models revolute joints (write three \
                                 hinges through the same point)"
                                    .to_owned(),
                            );
                        }
                        (true, _) => {
                            return unsupported(
                                "a free joint on a child body (a second floating body): fbd \
                                 models one tree of revolute joints"
                                    .to_owned(),
                            );
                        }
                    }
                }
                "geom" => geoms.push(self.geom(child, &class)?),
                "site" => sites.push(child),
                "body" => children.push(child),
                "camera" | "light" => {}
                _ => {
                    return Err(unsupported(
                        place(file, child),
                        format!("<{tag}> in a body"),
                    ));
                }
            }
        }

        // The last hinge's point is the link's origin.
        let offset = hinges.last().map_or(Vector3::zeros(), |h| h.pos);
        let shift = Translation3::from(-offset);
        let mut link = RawLink::new(name.clone(), body_place.clone());
        link.inertial = self.inertial(inertial, &geoms)?.map(|mut i| {
            i.origin = shift * i.origin;
            i
        });
        for g in &geoms {
            if !g.collides {
                continue;
            }
            if g.kind == "sphere" && !g.from_mesh {
                if g.size[0] <= 0.0 {
                    return Err(bad_value(
                        g.place.clone(),
                        "size".to_owned(),
                        format!("{}", g.size[0]),
                        "a positive sphere radius".to_owned(),
                    ));
                }
                link.spheres.push(RawPoint {
                    name: g.name.clone(),
                    position: g.frame.translation.vector - offset,
                    radius: g.size[0],
                    place: g.place.clone(),
                });
            } else {
                link.other_collisions.push(g.place.clone());
            }
        }
        for s in sites {
            let el = El {
                node: s,
                defaults: Some(&self.class_of(s, &class)?.site),
            };
            let pos = match el.nums(file, "fromto", Some(6))? {
                Some(v) => Vector3::new(v[0] + v[3], v[1] + v[4], v[2] + v[5]) / 2.0,
                None => el.vec3_or(file, "pos", Vector3::zeros())?,
            };
            link.sites.push(RawPoint {
                name: s.attribute("name").map(str::to_owned),
                position: pos - offset,
                radius: 0.0,
                place: place(file, s),
            });
        }

        match parent {
            None => self.links.push(link),
            Some((parent_link, parent_offset)) => {
                let written = self.frame(&El::plain(node))?;
                let body_frame = Translation3::from(-parent_offset) * written;
                if hinges.is_empty() {
                    self.joints.push(RawJoint {
                        name: format!("{name}_fixed"),
                        place: body_place,
                        kind: RawJointKind::Fixed,
                        parent: parent_link.to_owned(),
                        child: name.clone(),
                        origin: body_frame,
                        axis: Vector3::z(),
                        effort: None,
                        velocity: None,
                    });
                    self.links.push(link.clone());
                }
                let k = hinges.len();
                let mut previous: Option<(String, Vector3<f64>)> = None;
                for (i, h) in hinges.into_iter().enumerate() {
                    let child = if i + 1 == k {
                        name.clone()
                    } else {
                        format!("{name}/{}", h.name)
                    };
                    let turn = UnitQuaternion::from_axis_angle(
                        &nalgebra::Unit::new_normalize(h.axis),
                        -h.reference,
                    );
                    let (from, origin) = match &previous {
                        None => (
                            parent_link.to_owned(),
                            body_frame * Translation3::from(h.pos) * turn,
                        ),
                        Some((prev, p)) => (prev.clone(), Translation3::from(h.pos - p) * turn),
                    };
                    if i + 1 == k {
                        self.links.push(link.clone());
                    } else {
                        self.links
                            .push(RawLink::new(child.clone(), h.place.clone()));
                    }
                    self.joints.push(RawJoint {
                        name: h.name,
                        place: h.place,
                        kind: RawJointKind::Revolute(h.limits),
                        parent: from,
                        child: child.clone(),
                        origin,
                        axis: h.axis,
                        effort: h.effort,
                        velocity: None,
                    });
                    previous = Some((child, h.pos));
                }
            }
        }
        for child in children {
            self.body(child, Some((&name, offset)), &class)?;
        }
        Ok(())
    }

    /// Hinge `el`, the `k`-th (from 1) of body `body`.
    fn hinge(&self, el: &El, body: &str, k: usize) -> Result<Hinge> {
        let file = self.file;
        let name = el
            .node
            .attribute("name")
            .map(str::to_owned)
            .unwrap_or_else(|| format!("{body}_hinge{k}"));
        let axis = el.vec3_or(file, "axis", Vector3::z())?;
        if axis.norm() < 1e-14 {
            return Err(el.bad(file, "axis", "a nonzero vector"));
        }
        let range = self.limited(el, "limited", "range")?;
        let limits = range.map(|[lo, hi]| JointLimits {
            lower: self.compiler.angle(lo),
            upper: self.compiler.angle(hi),
        });
        let effort = self
            .limited(el, "actuatorfrclimited", "actuatorfrcrange")?
            .map(|[lo, hi]| lo.abs().max(hi.abs()));
        Ok(Hinge {
            name,
            place: place(file, el.node),
            pos: el.vec3_or(file, "pos", Vector3::zeros())?,
            axis,
            reference: self.compiler.angle(el.num_or(file, "ref", 0.0)?),
            limits,
            effort,
        })
    }

    /// The range `[lo, hi]` of `el`'s `range` attribute if `limited`
    /// (`true`, `false` or `auto`) makes it active (MuJoCo's rules).
    fn limited(&self, el: &El, limited: &str, range: &str) -> Result<Option<[f64; 2]>> {
        let file = self.file;
        let written = el.nums(file, range, Some(2))?.map(|v| [v[0], v[1]]);
        let r = written.unwrap_or([0.0, 0.0]);
        let active = match el.choice(file, limited, &["true", "false", "auto"], "auto")? {
            "true" => true,
            "false" => false,
            _ => {
                if !self.compiler.autolimits && r != [0.0, 0.0] {
                    return Err(el.bad(
                        file,
                        range,
                        format!(
                            "{limited}=\"true\" or \"false\" with it: <compiler \
                             autolimits=\"false\"> infers no limits"
                        ),
                    ));
                }
                r[0] < r[1]
            }
        };
        if !active {
            return Ok(None);
        }
        if written.is_none() {
            return Err(missing(
                place(file, el.node),
                format!("attribute {range} ({limited}=\"true\")"),
            ));
        }
        if r[0] >= r[1] {
            return Err(el.bad(file, range, "a lower bound below the upper one"));
        }
        Ok(Some(r))
    }

    /// `<geom>` `node` with its class's defaults.
    fn geom(&self, node: Node<'a, 'i>, inherited: &str) -> Result<Geom> {
        let file = self.file;
        let el = El {
            node,
            defaults: Some(&self.class_of(node, inherited)?.geom),
        };
        let kind = el.choice(
            file,
            "type",
            &[
                "sphere",
                "capsule",
                "cylinder",
                "box",
                "ellipsoid",
                "plane",
                "hfield",
                "mesh",
                "sdf",
            ],
            "sphere",
        )?;
        let mut size = [0.0; 3];
        if let Some(v) = el.nums(file, "size", None)? {
            if v.is_empty() || v.len() > 3 {
                return Err(el.bad(file, "size", "one to three numbers"));
            }
            size[..v.len()].copy_from_slice(&v);
        }
        let mut frame = self.frame(&el)?;
        if let Some(v) = el.nums(file, "fromto", Some(6))? {
            if !["capsule", "cylinder", "box", "ellipsoid"].contains(&kind) {
                return Err(el.bad(
                    file,
                    "fromto",
                    "no fromto: it is for capsules, cylinders, boxes and ellipsoids",
                ));
            }
            if frame.translation.vector != Vector3::zeros() {
                return Err(el.bad(file, "fromto", "either pos or fromto, not both"));
            }
            let from = Vector3::new(v[0], v[1], v[2]);
            let to = Vector3::new(v[3], v[4], v[5]);
            let d = from - to;
            let half = d.norm() / 2.0;
            if half < 1e-14 {
                return Err(el.bad(file, "fromto", "two distinct points"));
            }
            size[1] = half;
            if kind == "box" || kind == "ellipsoid" {
                size[2] = half;
                size[1] = size[0];
            }
            frame = Isometry3::from_parts(Translation3::from((from + to) / 2.0), z_to(&d));
        }
        let contype = el.num_or(file, "contype", 1.0)?;
        let conaffinity = el.num_or(file, "conaffinity", 1.0)?;
        Ok(Geom {
            name: node.attribute("name").map(str::to_owned),
            place: place(file, node),
            kind,
            size,
            frame,
            collides: contype != 0.0 || conaffinity != 0.0,
            group: el.num_or(file, "group", 0.0)?,
            mass: el.nums(file, "mass", Some(1))?.map(|v| v[0]),
            density: el.num_or(file, "density", 1000.0)?,
            shell: el.choice(file, "shellinertia", &["true", "false"], "false")? == "true",
            from_mesh: kind == "mesh" || kind == "sdf" || el.text("mesh").is_some(),
        })
    }

    /// The body's mass properties (body coordinates): its `<inertial>`,
    /// or its geoms' as `inertiafromgeom` says.
    fn inertial(&self, node: Option<Node>, geoms: &[Geom]) -> Result<Option<RawInertial>> {
        let written = match node {
            None => None,
            Some(n) => Some(self.written_inertial(n)?),
        };
        let from_geoms = match self.compiler.from_geom {
            FromGeom::Always => true,
            FromGeom::Auto => written.is_none(),
            FromGeom::Never => false,
        };
        if !from_geoms {
            return Ok(written);
        }
        let mut mass = 0.0;
        let mut moment = Vector3::zeros();
        // About the body origin.
        let mut second = Matrix3::zeros();
        let [lo, hi] = self.compiler.group_range;
        for g in geoms {
            if g.group < lo || g.group > hi || g.mass == Some(0.0) {
                continue;
            }
            if g.mass.is_none() && g.density == 0.0 {
                continue;
            }
            let unsupported = |what: &str| {
                unsupported(
                    g.place.clone(),
                    format!(
                        "{what}, needed for the body's mass: give the body an <inertial> (or \
                     the geom mass=\"0\")"
                    ),
                )
            };
            if g.kind == "plane" {
                // No volume: no mass in MuJoCo either.
                continue;
            }
            if g.from_mesh {
                return Err(unsupported("a mesh geom (fbd reads no meshes)"));
            }
            if g.kind == "hfield" {
                return Err(unsupported("a height-field geom"));
            }
            if g.shell {
                return Err(unsupported("shellinertia=\"true\""));
            }
            let Some((volume, unit)) = solid(g.kind, g.size) else {
                return Err(bad_value(
                    g.place.clone(),
                    "size".to_owned(),
                    format!("{} {} {}", g.size[0], g.size[1], g.size[2]),
                    format!("positive sizes for a {}", g.kind),
                ));
            };
            let m = g.mass.unwrap_or(g.density * volume);
            if m < 0.0 {
                let attr = if g.mass.is_some() { "mass" } else { "density" };
                return Err(bad_value(
                    g.place.clone(),
                    attr.to_owned(),
                    format!("{}", g.mass.unwrap_or(g.density)),
                    "a non-negative value".to_owned(),
                ));
            }
            let r = g.frame.rotation.to_rotation_matrix().into_inner();
            let c = g.frame.translation.vector;
            let own = r * Matrix3::from_diagonal(&(unit * m)) * r.transpose();
            mass += m;
            moment += m * c;
            second += own + m * (Matrix3::identity() * c.norm_squared() - c * c.transpose());
        }
        if mass <= 0.0 {
            // No geom gives mass: MuJoCo keeps what is written.
            return Ok(written);
        }
        let com = moment / mass;
        let about_com =
            second - mass * (Matrix3::identity() * com.norm_squared() - com * com.transpose());
        Ok(Some(RawInertial {
            mass,
            origin: Isometry3::from_parts(Translation3::from(com), UnitQuaternion::identity()),
            inertia: 0.5 * (about_com + about_com.transpose()),
        }))
    }

    /// `<inertial>` `node` as written (body coordinates).
    fn written_inertial(&self, node: Node) -> Result<RawInertial> {
        let file = self.file;
        let el = El::plain(node);
        let Some(mass) = el.nums(file, "mass", Some(1))?.map(|v| v[0]) else {
            return Err(missing(place(file, node), "attribute mass".to_owned()));
        };
        xml::require(mass >= 0.0, file, node, "mass", "a non-negative mass")?;
        let diag = el.nums(file, "diaginertia", Some(3))?;
        let full = el.nums(file, "fullinertia", Some(6))?;
        let frame = self.frame(&el)?;
        let (inertia, frame) = match (diag, full) {
            (Some(d), None) => (
                Matrix3::from_diagonal(&Vector3::new(d[0], d[1], d[2])),
                frame,
            ),
            (None, Some(f)) => {
                if let Some(alt) = ALTERNATIVES.into_iter().find(|a| node.has_attribute(*a)) {
                    return Err(el.bad(
                        file,
                        alt,
                        "no orientation with fullinertia (its axes are the body's)",
                    ));
                }
                // MuJoCo replaces a written quat by the principal axes of
                // the full tensor, which is in the body's axes.
                let full = Matrix3::new(
                    f[0], f[3], f[4], //
                    f[3], f[1], f[5], //
                    f[4], f[5], f[2],
                );
                (
                    full,
                    Isometry3::from_parts(frame.translation, UnitQuaternion::identity()),
                )
            }
            (Some(_), Some(_)) => {
                return Err(el.bad(file, "fullinertia", "either diaginertia or fullinertia"));
            }
            (None, None) => {
                return Err(missing(
                    place(file, node),
                    "attribute diaginertia or fullinertia".to_owned(),
                ));
            }
        };
        Ok(RawInertial {
            mass,
            origin: frame,
            inertia,
        })
    }

    /// The actuators of every `<actuator>` section: none without a section
    /// (a passive model, as in MuJoCo).
    fn actuators(&self, root: Node) -> Result<Option<Vec<RawActuator>>> {
        let file = self.file;
        let sections: Vec<Node> = root
            .children()
            .filter(|n| n.has_tag_name("actuator"))
            .collect();
        if sections.is_empty() {
            return Ok(Some(Vec::new()));
        }
        let mut out = Vec::new();
        for node in sections
            .iter()
            .flat_map(|s| s.children().filter(Node::is_element))
        {
            let tag = node.tag_name().name();
            let unsupported = |what: String| Err(unsupported(place(file, node), what));
            if ![
                "motor",
                "position",
                "velocity",
                "general",
                "intvelocity",
                "damper",
            ]
            .contains(&tag)
            {
                return unsupported(format!(
                    "a <{tag}> actuator: fbd reads motor, position, velocity, intvelocity, \
                     general and damper actuators on joints"
                ));
            }
            let el = El {
                node,
                defaults: Some(&self.class_of(node, "main")?.actuator),
            };
            let joint = match ["joint", "jointinparent"]
                .into_iter()
                .find_map(|a| node.attribute(a))
            {
                Some(j) => j,
                None => {
                    if let Some(t) = ["tendon", "site", "body", "cranksite", "slidersite"]
                        .into_iter()
                        .find(|a| node.has_attribute(*a))
                    {
                        return unsupported(format!(
                            "a {t} transmission: fbd's actuators drive joints"
                        ));
                    }
                    return Err(missing(place(file, node), "attribute joint".to_owned()));
                }
            };
            let gear = el.nums(file, "gear", None)?.unwrap_or_else(|| vec![1.0]);
            if gear.is_empty() || gear.len() > 6 {
                return Err(el.bad(file, "gear", "one to six numbers"));
            }
            let effort_limit = self
                .limited(&el, "forcelimited", "forcerange")?
                .map(|[lo, hi]| lo.abs().max(hi.abs()) * gear[0].abs());
            out.push(RawActuator {
                name: node.attribute("name").unwrap_or(joint).to_owned(),
                joint: joint.to_owned(),
                effort_limit,
                place: place(file, node),
            });
        }
        Ok(Some(out))
    }
}

/// Volume and principal inertia per unit mass (about the centre, geom
/// axes) of a solid shape of MuJoCo `size`; `None` for a size that is not
/// positive where the shape needs it.
fn solid(kind: &str, size: [f64; 3]) -> Option<(f64, Vector3<f64>)> {
    use std::f64::consts::PI;
    let [a, b, c] = size;
    let positive = |xs: &[f64]| xs.iter().all(|&x| x > 0.0);
    match kind {
        "sphere" if positive(&[a]) => {
            Some((4.0 / 3.0 * PI * a.powi(3), Vector3::repeat(0.4 * a * a)))
        }
        "capsule" if positive(&[a, b]) => {
            let (r, h) = (a, 2.0 * b);
            let volume = PI * r * r * h + 4.0 / 3.0 * PI * r.powi(3);
            // Mass fractions of the two hemispheres and the cylinder.
            let ms = 4.0 * r / (4.0 * r + 3.0 * h);
            let mc = 1.0 - ms;
            let across = mc * (3.0 * r * r + h * h) / 12.0
                + ms * (0.4 * r * r + h * (3.0 * r + 2.0 * h) / 8.0);
            let along = mc * r * r / 2.0 + ms * 0.4 * r * r;
            Some((volume, Vector3::new(across, across, along)))
        }
        "cylinder" if positive(&[a, b]) => {
            let (r, h) = (a, 2.0 * b);
            let across = (3.0 * r * r + h * h) / 12.0;
            Some((PI * r * r * h, Vector3::new(across, across, r * r / 2.0)))
        }
        "box" if positive(&[a, b, c]) => Some((
            8.0 * a * b * c,
            Vector3::new(b * b + c * c, a * a + c * c, a * a + b * b) / 3.0,
        )),
        "ellipsoid" if positive(&[a, b, c]) => Some((
            4.0 / 3.0 * PI * a * b * c,
            Vector3::new(b * b + c * c, a * a + c * c, a * a + b * b) / 5.0,
        )),
        _ => None,
    }
}

/// An unsupported element.
fn unsupported(place: Place, what: impl Into<String>) -> RobotError {
    RobotError::Unsupported {
        place,
        what: what.into(),
    }
}

/// A missing attribute or element.
fn missing(place: Place, what: impl Into<String>) -> RobotError {
    RobotError::Missing {
        place,
        what: what.into(),
    }
}

/// Links and joints that do not form one tree.
fn tree_error(place: Place, message: impl Into<String>) -> RobotError {
    RobotError::Tree {
        place,
        message: message.into(),
    }
}

/// An attribute whose value is not what it must be.
fn bad_value(
    place: Place,
    attribute: impl Into<String>,
    value: impl Into<String>,
    expected: impl Into<String>,
) -> RobotError {
    RobotError::BadValue {
        place,
        attribute: attribute.into(),
        value: value.into(),
        expected: expected.into(),
    }
}
