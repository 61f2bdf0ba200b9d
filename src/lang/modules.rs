//! The module alphabet: lpfg's predefined modules and the user's declarations.

use std::collections::HashMap;

use super::value::Ty;

/// Index of a module kind in [`Alphabet`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Sym(pub u16);

/// The parameter signature of a module kind.
#[derive(Clone, Debug, PartialEq)]
pub enum Signature {
    /// A user module: exactly these types.
    Fixed(Vec<Ty>),
    /// A predefined module: any of these overloads (chosen by arity and type).
    Overloads(&'static [&'static [Ty]]),
}

#[derive(Clone, Debug)]
pub struct ModuleKind {
    pub name: String,
    pub sig: Signature,
    pub builtin: bool,
}

/// All module kinds known to a program. The predefined ones come first.
#[derive(Clone, Debug)]
pub struct Alphabet {
    pub kinds: Vec<ModuleKind>,
    /// Each kind's symbol by name (the first of a name), so that a lookup
    /// does not walk a long alphabet.
    index: HashMap<String, Sym>,
}

use Ty::{Float as F, Int as I, V2, V3};

const NONE: &[&[Ty]] = &[&[]];
const ONE_F: &[&[Ty]] = &[&[F]];
const OPT_F: &[&[Ty]] = &[&[F], &[]];
const ONE_I: &[&[Ty]] = &[&[I]];
/// lpfg's `MoveTo(x, y, z)`, or a point as in Velho's `LineTo(v)`.
const XYZ: &[&[Ty]] = &[&[F, F, F], &[V2]];
const P2: &[&[Ty]] = &[&[V2]];
const P3: &[&[Ty]] = &[&[V3]];
const P2D: &[&[Ty]] = &[&[Ty::V2d]];
const P3D: &[&[Ty]] = &[&[Ty::V3d]];
const L2D: &[&[Ty]] = &[&[Ty::V2d, Ty::V2d]];
const L3D: &[&[Ty]] = &[&[Ty::V3d, Ty::V3d]];
const L2: &[&[Ty]] = &[&[V2, V2]];
const L3: &[&[Ty]] = &[&[V3, V3]];
const FF: &[&[Ty]] = &[&[F, F]];
const AXIS_ANGLE: &[&[Ty]] = &[&[V3, F]];
const HEAD: &[&[Ty]] = &[&[F, F, F, F, F, F]];
const FFF: &[&[Ty]] = &[&[F, F, F]];
const STR: &[&[Ty]] = &[&[Ty::Str]];
const IF: &[&[Ty]] = &[&[I, F]];
const IFFF: &[&[Ty]] = &[&[I, F, F, F]];
const IFF: &[&[Ty]] = &[&[I, F, F]];
const III: &[&[Ty]] = &[&[I, I, I]];

/// lpfg's predefined modules (`lpfgall.h`), plus `#` and Velho's `LineTo(v)`.
pub const PREDEFINED: &[(&str, &[&[Ty]])] = &[
    ("#", NONE),
    ("F", OPT_F),
    ("f", OPT_F),
    ("G", OPT_F),
    ("g", OPT_F),
    ("MoveTo", XYZ),
    ("MoveTo2f", P2),
    ("MoveTo2d", P2D),
    ("MoveTo3f", P3),
    ("MoveTo3d", P3D),
    ("MoveRel2f", P2),
    ("MoveRel2d", P2D),
    ("MoveRel3f", P3),
    ("MoveRel3d", P3D),
    ("LineTo", XYZ),
    ("LineTo2f", P2),
    ("LineTo2d", P2D),
    ("LineTo3f", P3),
    ("LineTo3d", P3D),
    ("LineRel2f", P2),
    ("LineRel2d", P2D),
    ("LineRel3f", P3),
    ("LineRel3d", P3D),
    ("Line2f", L2),
    ("Line2d", L2D),
    ("Line3f", L3),
    ("Line3d", L3D),
    ("SetCoordinateSystem", ONE_F),
    ("Left", OPT_F),
    ("Right", OPT_F),
    ("Up", OPT_F),
    ("Down", OPT_F),
    ("RollL", OPT_F),
    ("RollR", OPT_F),
    ("TurnAround", NONE),
    ("RollToVert", NONE),
    ("RotateXYZ", AXIS_ANGLE),
    ("RotateHLU", AXIS_ANGLE),
    ("Rotate", AXIS_ANGLE),
    ("SetHead", HEAD),
    ("SetHead3f", P3),
    ("IncColor", NONE),
    ("DecColor", NONE),
    ("SetColor", &[&[I], &[I, I, I]]),
    ("SetWidth", ONE_F),
    ("SB", NONE),
    ("EB", NONE),
    ("Cut", NONE),
    // What `propensity E produce ...;` emits before its successor
    // (manual 7.2): a Gillespie step reads the reactions back from it.
    ("Propensity", ONE_F),
    ("Circle0", NONE),
    ("CircleFront0", NONE),
    ("Circle", ONE_F),
    ("CircleFront", ONE_F),
    ("CircleB", ONE_F),
    ("CircleFrontB", ONE_F),
    ("Sphere0", NONE),
    ("Sphere", ONE_F),
    ("SP", NONE),
    ("PP", NONE),
    ("EP", NONE),
    ("Rhombus", FF),
    ("Triangle", FF),
    ("Label", STR),
    ("Surface", IF),
    ("Surface3", IFFF),
    ("Mesh", IF),
    ("Mesh3", IFFF),
    ("ContourSides", ONE_I),
    ("CurrentContour", ONE_I),
    ("BlendedContour", IFF),
    ("ScaleContour", FF),
    ("StartGC", NONE),
    ("PointGC", NONE),
    ("EndGC", NONE),
    ("CurrentTexture", ONE_I),
    ("TextureVCoeff", ONE_F),
    ("Elasticity", ONE_F),
    ("SetElasticity", IF),
    ("IncElasticity", ONE_I),
    ("DecElasticity", ONE_I),
    ("SetTropismDirection3f", P3),
    ("ContourNormal", P3),
    ("BSurface", IF),
    ("Orient", NONE),
    ("GetPos", FFF),
    ("GetHead", FFF),
    ("GetLeft", FFF),
    ("GetUp", FFF),
    ("E1", ONE_F),
    ("E2", FF),
    ("EA20", &[&[Ty::Struct(super::value::EA20_ARRAY)]]),
    ("Camera", NONE),
    ("MouseIns", NONE),
    ("MouseInsPos", &[&[Ty::Struct(super::value::MOUSE_STATUS)]]),
    ("Terrain", &[&[Ty::Struct(super::value::CAMERA_POSITION)]]),
    ("SetUPrecision", ONE_F),
    ("SetVPrecision", ONE_F),
    ("InitSurface", ONE_I),
    ("SurfacePoint", III),
    ("DrawSurface", ONE_I),
];

/// lpfg's predefined modules that subgram does not have yet, with what
/// they are for: a program that uses one is told so, not asked to declare
/// it.
pub const NOT_YET: &[(&str, &str)] = &[
    ("DSurface", "it draws a dynamic surface (manual 7.1)"),
    (
        "DBSurfaceS",
        "it draws a dynamic B-spline surface (manual 10.1)",
    ),
    (
        "DBSurfaceM",
        "it draws a dynamic B-spline surface (manual 10.1)",
    ),
    ("PovRayStart", "it starts POV-Ray output"),
];

/// The message for a module that is neither declared nor predefined;
/// `hint` ("; did you mean `Apex`?", or nothing) follows, except for an
/// lpfg module that is not supported yet.
pub fn undeclared(name: &str, params: &str, hint: &str) -> String {
    match NOT_YET.iter().find(|(n, _)| *n == name) {
        Some((_, what)) => {
            format!("`{name}` is an lpfg module that subgram does not support yet: {what}")
        }
        None => format!(
            "undeclared module `{name}`: declare it before use, e.g. `module {name}({params});`{hint}"
        ),
    }
}

impl Alphabet {
    pub fn new() -> Alphabet {
        let mut a = Alphabet {
            kinds: Vec::new(),
            index: HashMap::new(),
        };
        for (name, sig) in PREDEFINED {
            a.push(ModuleKind {
                name: (*name).to_string(),
                sig: Signature::Overloads(sig),
                builtin: true,
            });
        }
        a
    }

    fn push(&mut self, kind: ModuleKind) -> Sym {
        let sym = Sym(self.kinds.len() as u16);
        self.index.entry(kind.name.clone()).or_insert(sym);
        self.kinds.push(kind);
        sym
    }

    pub fn lookup(&self, name: &str) -> Option<Sym> {
        self.index.get(name).copied()
    }

    pub fn get(&self, s: Sym) -> &ModuleKind {
        &self.kinds[s.0 as usize]
    }

    pub fn name(&self, s: Sym) -> &str {
        &self.kinds[s.0 as usize].name
    }

    /// The symbol of a predefined module; panics if the table lacks it.
    pub fn builtin(&self, name: &str) -> Sym {
        self.lookup(name).expect("predefined module")
    }

    /// The parameter types of a module of kind `s` whose parameters take
    /// `width` slots. The overloads of a predefined module differ in width.
    pub fn layout(&self, s: Sym, width: usize, structs: &[super::value::StructDef]) -> &[Ty] {
        match &self.kinds[s.0 as usize].sig {
            Signature::Fixed(t) => t,
            Signature::Overloads(o) => o
                .iter()
                .find(|tys| {
                    tys.iter()
                        .map(|t| super::value::width(*t, structs))
                        .sum::<usize>()
                        == width
                })
                .copied()
                .unwrap_or(&[]),
        }
    }

    /// Declares a module kind; the checker keeps their number within
    /// what a [`Sym`] can index.
    pub fn declare(&mut self, name: &str, params: Vec<Ty>) -> Sym {
        self.push(ModuleKind {
            name: name.to_string(),
            sig: Signature::Fixed(params),
            builtin: false,
        })
    }
}

impl Default for Alphabet {
    fn default() -> Self {
        Alphabet::new()
    }
}
