//! The host built-ins of the stellar topology: each one's name and
//! signature, and the table the language's checker reads them from.

use crate::lang::builtins::{Builtin, HostTable, SigError};
use crate::lang::ir::Func;
use crate::lang::value::{Ty, Value};

use super::{id, EDGE, FACE, SET, VERTEX};

fn one(a: &[Ty], kinds: &[u8], what: &str) -> Result<(), SigError> {
    match a {
        [Ty::Elem(k)] if kinds.contains(k) => Ok(()),
        [_] => Err(SigError::Message(what.into())),
        _ => Err(SigError::Arity(1)),
    }
}

const V: Ty = Ty::Elem(VERTEX);

static FUNCTIONS: &[Builtin] = &[
    Builtin {
        name: "l",
        resolve: |a| {
            one(
                a,
                &[VERTEX, EDGE, FACE],
                "`l` takes a vertex, an edge or a face",
            )?;
            Ok((Func::Host(id::LEVEL), Ty::Int))
        },
    },
    Builtin {
        name: "pos",
        resolve: |a| {
            one(a, &[VERTEX], "`pos` takes a vertex")?;
            Ok((Func::Host(id::POS), Ty::V3d))
        },
    },
    Builtin {
        name: "valence",
        resolve: |a| {
            one(a, &[VERTEX], "`valence` takes a vertex")?;
            Ok((Func::Host(id::VALENCE), Ty::Int))
        },
    },
    Builtin {
        name: "deg",
        resolve: |a| {
            one(a, &[VERTEX], "`deg` takes a vertex")?;
            Ok((Func::Host(id::VALENCE), Ty::Int))
        },
    },
    Builtin {
        name: "boundary",
        resolve: |a| {
            one(
                a,
                &[VERTEX, EDGE, FACE],
                "`boundary` takes a vertex, an edge or a face",
            )?;
            Ok((Func::Host(id::BOUNDARY), Ty::Bool))
        },
    },
    Builtin {
        name: "block",
        resolve: |a| {
            one(
                a,
                &[EDGE, FACE],
                "`block` takes an edge (true for the internal edge of a basic block) \
                 or a face (true for half of a block)",
            )?;
            Ok((Func::Host(id::BLOCK), Ty::Bool))
        },
    },
    Builtin {
        name: "lone",
        resolve: |a| {
            one(
                a,
                &[EDGE, FACE],
                "`lone` takes a face (true for a triangle in no basic block) or an edge (true \
                 for an edge of such a triangle; on the boundary only its first boundary edge)",
            )?;
            Ok((Func::Host(id::LONE), Ty::Bool))
        },
    },
    Builtin {
        name: "transversal",
        resolve: |a| {
            one(
                a,
                &[EDGE],
                "`transversal` takes an edge: true for an edge that an edge split drew to an \
                 opposite vertex",
            )?;
            Ok((Func::Host(id::TRANSVERSAL), Ty::Bool))
        },
    },
    Builtin {
        name: "new",
        resolve: |a| {
            one(
                a,
                &[VERTEX],
                "`new` takes a vertex: true for a vertex made in this step",
            )?;
            Ok((Func::Host(id::NEW), Ty::Bool))
        },
    },
    Builtin {
        name: "center",
        resolve: |a| {
            one(
                a,
                &[VERTEX],
                "`center` takes a vertex: true for the centre of a dual block, whose edges are \
                 all internal edges of blocks",
            )?;
            Ok((Func::Host(id::CENTER), Ty::Bool))
        },
    },
    Builtin {
        name: "centre",
        resolve: |a| {
            one(
                a,
                &[VERTEX],
                "`centre` takes a vertex: true for the centre of a dual block, whose edges are \
                 all internal edges of blocks",
            )?;
            Ok((Func::Host(id::CENTER), Ty::Bool))
        },
    },
    Builtin {
        name: "avg",
        resolve: |a| {
            one(
                a,
                &[EDGE, FACE],
                "`avg` takes an edge, a face or a set of vertices",
            )?;
            Ok((Func::Host(id::AVG_OF), Ty::V3d))
        },
    },
    Builtin {
        name: "ring",
        resolve: |a| {
            one(a, &[VERTEX], "`ring` takes a vertex")?;
            Ok((Func::Host(id::RING), Ty::Elem(SET)))
        },
    },
    Builtin {
        name: "N1",
        resolve: |a| {
            one(a, &[VERTEX], "`N1` takes a vertex")?;
            Ok((Func::Host(id::RING), Ty::Elem(SET)))
        },
    },
    Builtin {
        name: "boundary_ring",
        resolve: |a| {
            one(a, &[VERTEX], "`boundary_ring` takes a vertex")?;
            Ok((Func::Host(id::BOUNDARY_RING), Ty::Elem(SET)))
        },
    },
    Builtin {
        name: "verts",
        resolve: |a| {
            one(a, &[EDGE, FACE], "`verts` takes an edge or a face")?;
            Ok((Func::Host(id::VERTS), Ty::Elem(SET)))
        },
    },
    Builtin {
        name: "tail",
        resolve: |a| {
            one(a, &[EDGE], "`tail` takes an edge")?;
            Ok((Func::Host(id::TAIL), V))
        },
    },
    Builtin {
        name: "head",
        resolve: |a| {
            one(a, &[EDGE], "`head` takes an edge")?;
            Ok((Func::Host(id::HEAD), V))
        },
    },
    Builtin {
        name: "bnext",
        resolve: |a| {
            one(a, &[VERTEX], "`bnext` takes a boundary vertex")?;
            Ok((Func::Host(id::BNEXT), V))
        },
    },
    Builtin {
        name: "bprev",
        resolve: |a| {
            one(a, &[VERTEX], "`bprev` takes a boundary vertex")?;
            Ok((Func::Host(id::BPREV), V))
        },
    },
    Builtin {
        name: "sharp",
        resolve: |a| {
            one(
                a,
                &[VERTEX, EDGE],
                "`sharp` takes an edge (true for a crease: sharpness above 0) or a vertex \
                 (true for a corner by its own sharpness)",
            )?;
            Ok((Func::Host(id::SHARP), Ty::Bool))
        },
    },
    Builtin {
        name: "sharpness",
        resolve: |a| match a {
            [V, V] => Ok((Func::Host(id::SHARPNESS_BETWEEN), Ty::Double)),
            [_, _] => Err(SigError::Message(
                "`sharpness` of two vertices is that of the edge between them: it takes two \
                 vertices"
                    .into(),
            )),
            _ => {
                one(
                    a,
                    &[VERTEX, EDGE],
                    "`sharpness` takes an edge or a vertex (0 smooth, more for a crease or a \
                     corner, `inf` for ever), or two vertices",
                )?;
                Ok((Func::Host(id::SHARPNESS), Ty::Double))
            }
        },
    },
    Builtin {
        name: "next_sharpness",
        resolve: |a| match a {
            [V, V] => Ok((Func::Host(id::NEXT_SHARPNESS), Ty::Double)),
            _ => Err(SigError::Message(
                "`next_sharpness(v, w)` takes two vertices: the sharpness the half at v of the \
                 edge between them has one level down (by the grammar's `creasing:` method)"
                    .into(),
            )),
        },
    },
    Builtin {
        name: "creases",
        resolve: |a| {
            one(
                a,
                &[VERTEX],
                "`creases` takes a vertex: the number of sharp edges at it (off the boundary)",
            )?;
            Ok((Func::Host(id::CREASES), Ty::Int))
        },
    },
    Builtin {
        name: "crease_ring",
        resolve: |a| {
            one(
                a,
                &[VERTEX],
                "`crease_ring` takes a vertex: its neighbours across sharp edges (off the \
                 boundary)",
            )?;
            Ok((Func::Host(id::CREASE_RING), Ty::Elem(SET)))
        },
    },
    Builtin {
        name: "crease_weight",
        resolve: |a| {
            one(
                a,
                &[VERTEX],
                "`crease_weight` takes a vertex: the weight of its crease or corner rule at this \
                 level",
            )?;
            Ok((Func::Host(id::CREASE_WEIGHT), Ty::Double))
        },
    },
    Builtin {
        name: "point",
        resolve: |a| match a {
            [x, y, z] if x.is_numeric() && y.is_numeric() && z.is_numeric() => {
                Ok((Func::Host(id::POINT), Ty::V3d))
            }
            [_, _, _] => Err(SigError::Message("`point` takes three numbers".into())),
            _ => Err(SigError::Arity(3)),
        },
    },
    // What adaptive refinement selects by (`adaptive;`), read from the
    // positions as they are when the rule starts.
    Builtin {
        name: "area",
        resolve: |a| {
            one(
                a,
                &[EDGE, FACE],
                "`area` takes a face (its area) or an edge (the area of the faces beside it: \
                 a block's, for its internal edge)",
            )?;
            Ok((Func::Host(id::AREA), Ty::Double))
        },
    },
    Builtin {
        name: "length",
        resolve: |a| {
            one(
                a,
                &[EDGE],
                "`length` takes an edge (for the length of a vector, use `Length`)",
            )?;
            Ok((Func::Host(id::LENGTH), Ty::Double))
        },
    },
    Builtin {
        name: "angle",
        resolve: |a| {
            one(
                a,
                &[EDGE],
                "`angle` takes an edge: the angle in degrees between the normals of the two \
                 faces beside it (0 on the boundary)",
            )?;
            Ok((Func::Host(id::ANGLE), Ty::Double))
        },
    },
    Builtin {
        name: "refined",
        resolve: |a| {
            one(
                a,
                &[VERTEX],
                "`refined` takes a vertex: true when every face around it has a corner made \
                 in this step",
            )?;
            Ok((Func::Host(id::REFINED), Ty::Bool))
        },
    },
];

/// The table of the stellar topology.
pub static SURFACE_HOST: HostTable = HostTable {
    name: "surface grammar",
    elements: &["a vertex", "an edge", "a face", "a set of vertices"],
    functions: FUNCTIONS,
    values: &[
        ("c", Func::Host(id::CURRENT), Ty::Int),
        ("step", Func::Host(id::STEP), Ty::Int),
    ],
    arith: |k| (k == VERTEX).then_some((Func::Host(id::POS), Ty::V3d)),
    members: |k| (k == SET).then_some(VERTEX),
    types: &[],
    zero: |_| Value::Void,
    fresh: |_| None,
    properties: None,
};
