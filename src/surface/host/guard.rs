//! [`Guard`]: a rule's condition recognised in the checked IR and tested
//! without the interpreter where it can be.

use crate::lang::eval::RuntimeError;
use crate::lang::ir::{Ex, Func};
use crate::lang::value::{Elem, Value};
use crate::mesh::VertexId;

use super::mesh_host::{cmp, op_code};
use super::{id, vertex, vertex_of, Evaluate, EDGE};

/// The vertex or element a guard leaf reads: the rule's element, or an end
/// of it (`tail(e)`, `head(e)`).
#[derive(Clone, Copy, Debug)]
pub enum Path {
    Elem,
    End(bool),
}

/// A guard recognised in the checked IR and tested without the
/// interpreter where it can be: leaves that read the rule's element (its
/// marks, its level against `c`, whether it or an end of it is new), and
/// leaves that do not depend on the element at all (`step % 2 == 0`),
/// which the interpreter evaluates once per rule and the guard remembers.
/// The same meaning as the expression it came from, as a curve stencil is
/// for its body.
#[derive(Clone, Debug)]
pub enum Guard {
    /// `l(x) OP c`, by the operator's code.
    Level(i64, Path),
    /// A built-in that takes the element (or an end) and gives a bool.
    Test(u16, Path),
    /// An integer built-in of a vertex (`valence`, `creases`) against a
    /// constant: the built-in, the operator's code, the constant.
    Count(u16, i64, i64, Path),
    /// An expression that reads no element.
    Invariant(Box<Ex>),
    Not(Box<Guard>),
    And(Box<Guard>, Box<Guard>),
    Or(Box<Guard>, Box<Guard>),
}

fn path(e: &Ex, slot: u16) -> Option<Path> {
    match e {
        Ex::Local(s) if *s == slot => Some(Path::Elem),
        Ex::Call(Func::Host(f @ (id::TAIL | id::HEAD)), args, _) => match args.as_slice() {
            [Ex::Local(s)] if *s == slot => Some(Path::End(*f == id::HEAD)),
            _ => None,
        },
        _ => None,
    }
}

/// True when `e` reads no local and no element: its value is the same for
/// every element a rule tests.
fn invariant(e: &Ex) -> bool {
    let mut ok = true;
    e.walk(&mut |x| match x {
        Ex::Local(_) | Ex::Global(_) | Ex::Assign(..) | Ex::IncDec(..) | Ex::InContext(..) => {
            ok = false
        }
        Ex::Call(Func::Host(f), ..) if !matches!(*f, id::CURRENT | id::STEP) => ok = false,
        Ex::Call(Func::Random(_) | Func::UseGroup | Func::Stop, ..) => ok = false,
        _ => {}
    });
    ok
}

impl Guard {
    /// The guard of condition `e` on the element in local `slot`, if `e`
    /// has that form. A guard that is only invariant leaves is not worth
    /// one: None.
    pub fn of(e: &Ex, slot: u16) -> Option<Guard> {
        let g = Guard::leaf(e, slot)?;
        (!g.is_invariant()).then_some(g)
    }

    fn is_invariant(&self) -> bool {
        match self {
            Guard::Invariant(_) => true,
            Guard::Level(..) | Guard::Test(..) | Guard::Count(..) => false,
            Guard::Not(a) => a.is_invariant(),
            Guard::And(a, b) | Guard::Or(a, b) => a.is_invariant() && b.is_invariant(),
        }
    }

    fn leaf(e: &Ex, slot: u16) -> Option<Guard> {
        if invariant(e) {
            return Some(Guard::Invariant(Box::new(e.clone())));
        }
        Some(match e {
            Ex::Call(Func::Host(id::LEVEL_VS_CURRENT), args, _) => match args.as_slice() {
                [x, Ex::Const(Value::Int(op))] => Guard::Level(*op, path(x, slot)?),
                _ => return None,
            },
            Ex::Call(
                Func::Host(
                    f @ (id::BOUNDARY
                    | id::BLOCK
                    | id::TRANSVERSAL
                    | id::NEW
                    | id::CENTER
                    | id::SHARP),
                ),
                args,
                _,
            ) => match args.as_slice() {
                [x] => Guard::Test(*f, path(x, slot)?),
                _ => return None,
            },
            Ex::Bin(op, a, b, _) => match (op_code(*op), &**a, &**b) {
                (
                    Some(code),
                    Ex::Call(Func::Host(f @ (id::VALENCE | id::CREASES)), args, _),
                    Ex::Const(Value::Int(k)),
                ) => match args.as_slice() {
                    [x] => Guard::Count(*f, code, *k, path(x, slot)?),
                    _ => return None,
                },
                _ => return None,
            },
            Ex::Not(a) => Guard::Not(Box::new(Guard::leaf(a, slot)?)),
            Ex::Logic(and, a, b) => {
                let (a, b) = (
                    Box::new(Guard::leaf(a, slot)?),
                    Box::new(Guard::leaf(b, slot)?),
                );
                if *and {
                    Guard::And(a, b)
                } else {
                    Guard::Or(a, b)
                }
            }
            // A call of an inlined function of no parameters, such as
            // `even()`, is an invariant above; with parameters bound to
            // the element it is left to the interpreter.
            _ => return None,
        })
    }

    /// True when the guard is false for every element of a mesh with no
    /// sharpness (`sharp(x)`, `creases(v) >= 2`, in a conjunction), and it
    /// has no leaf the interpreter evaluates (which could fail): a rule
    /// with such a guard matches nothing there, so it need not look.
    pub fn never_without_creases(&self) -> bool {
        fn no_invariant(g: &Guard) -> bool {
            match g {
                Guard::Invariant(_) => false,
                Guard::Level(..) | Guard::Test(..) | Guard::Count(..) => true,
                Guard::Not(a) => no_invariant(a),
                Guard::And(a, b) | Guard::Or(a, b) => no_invariant(a) && no_invariant(b),
            }
        }
        fn never(g: &Guard) -> bool {
            match g {
                Guard::Test(id::SHARP, _) => true,
                Guard::Count(id::CREASES, op, k, _) => !match op {
                    0 => 0 < *k,
                    1 => 0 <= *k,
                    2 => 0 > *k,
                    3 => 0 >= *k,
                    4 => 0 == *k,
                    _ => 0 != *k,
                },
                Guard::And(a, b) => never(a) || never(b),
                Guard::Or(a, b) => never(a) && never(b),
                _ => false,
            }
        }
        no_invariant(self) && never(self)
    }

    pub fn test(&self, ev: &mut dyn Evaluate<'_>, elem: &Elem) -> Result<bool, RuntimeError> {
        Ok(match self {
            Guard::Level(op, p) => {
                let host = ev.host();
                host.elem_level(&Guard::at(*p, elem))
                    .is_some_and(|l| cmp(*op, l, host.current))
            }
            Guard::Test(f, p) => ev.host().test(*f, &Guard::at(*p, elem)),
            Guard::Count(f, op, k, p) => {
                let host = ev.host();
                // What the call gives for something that is not a vertex.
                let n = vertex_of(&Guard::at(*p, elem)).map_or(0, |v| match *f {
                    id::VALENCE => host.mesh.valence(v) as i64,
                    _ => host.mesh.sharp_edge_count(v) as i64,
                });
                match op {
                    0 => n < *k,
                    1 => n <= *k,
                    2 => n > *k,
                    3 => n >= *k,
                    4 => n == *k,
                    _ => n != *k,
                }
            }
            Guard::Invariant(x) => {
                let key = &**x as *const Ex as usize;
                if let Some((_, b)) = ev.memo().invariants.iter().find(|(k, _)| *k == key) {
                    *b
                } else {
                    let b = ev.eval(x)?.truthy();
                    ev.memo().invariants.push((key, b));
                    b
                }
            }
            Guard::Not(a) => !a.test(ev, elem)?,
            Guard::And(a, b) => a.test(ev, elem)? && b.test(ev, elem)?,
            Guard::Or(a, b) => a.test(ev, elem)? || b.test(ev, elem)?,
        })
    }

    /// The element a leaf reads. An end of something that is not an edge
    /// is no element: the leaf reads as false, as `l` and the tests do
    /// for values that are not theirs.
    fn at(p: Path, elem: &Elem) -> Elem {
        match p {
            Path::Elem => *elem,
            Path::End(head) if elem.kind == EDGE => vertex(VertexId(elem.ids[head as usize])),
            Path::End(_) => Elem {
                kind: u8::MAX,
                flags: 0,
                ids: [0; 4],
            },
        }
    }
}
