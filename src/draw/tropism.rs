//! lpfg's tropisms (manual 5.11 and 8.1.4): the view file's `tropism:`,
//! `torque:` and `stropism:` commands bend the turtle's heading a little
//! at every `F` and `f`, as lpfg's turtle does; `SetElasticity`,
//! `IncElasticity`, `DecElasticity`, `Elasticity` and
//! `SetTropismDirection3f` change them while the turtle walks.
//!
//! The formulas are lpfg's (vlab 9bf820d), quirks included: the sum of
//! the tropisms' directions is global to an interpretation and is
//! recomputed from the turtle's own elasticities when a branch ends, and
//! the simple tropism turns the heading by the cosines of its angles.

use glam::DVec3;

use super::EPSILON;

/// A `tropism:` or `torque:` command of the view file.
#[derive(Clone, Debug, PartialEq)]
pub struct Tropism {
    /// `torque:` (turns the up vector about the heading) rather than
    /// `tropism:`.
    pub torque: bool,
    /// `T:` scaled by the intensity `I:`.
    pub direction: DVec3,
    /// `A:`, the angle the segments try to reach, in radians.
    pub angle: f64,
    /// `E:`, the initial elasticity.
    pub elasticity: f64,
    /// `S:`, the step of `IncElasticity` and `DecElasticity`.
    pub step: f64,
}

/// The view file's `stropism: x y z, e`: direction and elasticity. The
/// default pulls along +y with no elasticity, so it does nothing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SimpleTropism {
    pub direction: DVec3,
    pub elasticity: f64,
}

impl Default for SimpleTropism {
    fn default() -> Self {
        SimpleTropism {
            direction: DVec3::Y,
            elasticity: 0.0,
        }
    }
}

/// The tropisms of a view file.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Tropisms {
    pub list: Vec<Tropism>,
    pub simple: SimpleTropism,
}

impl Tropism {
    /// The text after `tropism:` or `torque:`: `T: x y z` and optional
    /// `A: a`, `I: i`, `E: e`, `S: s`, read as lpfg reads them (a letter
    /// and the character after it, then numbers, each the start of a
    /// blank-separated word: `A:90` and `T: 1 0 0` are read, `T: 0,1,0` is
    /// not). `None` when it cannot be read, or when lpfg refuses it (a null
    /// direction, an angle beyond 180 degrees, a zero intensity, an angle
    /// for a torque).
    pub fn parse(text: &str, torque: bool) -> Option<Tropism> {
        let mut t = Tropism {
            torque,
            direction: DVec3::NEG_Y,
            angle: 0.0,
            elasticity: 0.0,
            step: 0.0,
        };
        let mut intensity = 1.0;
        let mut rest = text.trim_start();
        while let Some(letter) = rest.chars().next() {
            // The letter and the character after it (the colon).
            let after = rest.char_indices().nth(2).map_or("", |(i, _)| &rest[i..]);
            let count = if letter == 'T' { 3 } else { 1 };
            let (v, r) = read_floats(after, count)?;
            rest = r;
            match letter {
                'T' => {
                    t.direction = DVec3::new(v[0], v[1], v[2]);
                    if t.direction == DVec3::ZERO {
                        return None;
                    }
                }
                'A' if !torque => {
                    if !(-180.0..=180.0).contains(&v[0]) {
                        return None;
                    }
                    t.angle = v[0].to_radians();
                }
                'I' if v[0] != 0.0 => intensity = v[0],
                'E' => t.elasticity = v[0],
                'S' => t.step = v[0],
                _ => return None,
            }
        }
        t.direction *= intensity;
        Some(t)
    }
}

/// `count` numbers at the start of `text`'s blank-separated words, as C's
/// `sscanf("%f")` reads each (`0,1` reads 0), and the text after them.
fn read_floats(text: &str, count: usize) -> Option<(Vec<f64>, &str)> {
    let mut text = text.trim_start();
    let mut v = Vec::with_capacity(count);
    for _ in 0..count {
        let end = text.find(char::is_whitespace).unwrap_or(text.len());
        v.push(leading_float(&text[..end])?);
        text = text[end..].trim_start();
    }
    Some((v, text))
}

/// The longest start of `word` that is a number.
fn leading_float(word: &str) -> Option<f64> {
    let ends: Vec<usize> = word
        .char_indices()
        .map(|(i, c)| i + c.len_utf8())
        .take(64)
        .collect();
    ends.iter()
        .rev()
        .find_map(|&e| word[..e].parse::<f64>().ok())
        .filter(|x| x.is_finite())
}

impl SimpleTropism {
    /// The text after `stropism:`: `x y z, e`.
    pub fn parse(text: &str) -> Option<SimpleTropism> {
        let (v, e) = text.split_once(',')?;
        let v: Vec<f64> = v
            .split_whitespace()
            .map(|w| w.parse().ok())
            .collect::<Option<_>>()?;
        let [x, y, z] = v[..] else { return None };
        Some(SimpleTropism {
            direction: DVec3::new(x, y, z),
            elasticity: e.trim().parse().ok()?,
        })
    }
}

/// The tropisms' state shared by the whole interpretation (lpfg's global
/// tropism array): the current elasticities, the sum of the directions
/// weighted by them, and the torques' twist.
#[derive(Clone, Debug)]
pub(super) struct Field<'t> {
    tropisms: &'t [Tropism],
    elasticity: Vec<f64>,
    global: DVec3,
    twist: DVec3,
}

impl<'t> Field<'t> {
    pub(super) fn new(tropisms: &'t [Tropism]) -> Field<'t> {
        let mut f = Field {
            tropisms,
            elasticity: tropisms.iter().map(|t| t.elasticity).collect(),
            global: DVec3::ZERO,
            twist: DVec3::ZERO,
        };
        for t in tropisms {
            if t.torque {
                f.twist += t.direction * t.elasticity;
            } else {
                f.global += t.direction * t.angle.cos() * t.elasticity;
            }
        }
        f
    }

    /// The elasticities a new turtle starts with.
    pub(super) fn initial(&self) -> Vec<f64> {
        self.elasticity.clone()
    }

    /// `SetElasticity(id, e)`; ignored for an id the view file lacks.
    /// Returns whether it applied.
    pub(super) fn set(&mut self, id: i64, e: f64) -> bool {
        let Some(t) = usize::try_from(id).ok().and_then(|i| self.tropisms.get(i)) else {
            return false;
        };
        let i = id as usize;
        let de = e - self.elasticity[i];
        self.elasticity[i] = e;
        self.global += t.direction * de * t.angle.cos();
        true
    }

    /// The elasticity of tropism `id` after `IncElasticity` (`sign` 1) or
    /// `DecElasticity` (-1).
    pub(super) fn stepped(&self, id: i64, sign: f64) -> Option<f64> {
        let i = usize::try_from(id).ok()?;
        let t = self.tropisms.get(i)?;
        Some(self.elasticity[i] + sign * t.step)
    }

    /// A branch ended: the elasticities are the restored turtle's, and the
    /// sum is recomputed from them (over torques too, as lpfg does).
    pub(super) fn restore(&mut self, elasticity: &[f64]) {
        self.global = DVec3::ZERO;
        for (i, t) in self.tropisms.iter().enumerate() {
            let e = elasticity.get(i).copied().unwrap_or(0.0);
            self.elasticity[i] = e;
            self.global += t.direction * t.angle.cos() * e;
        }
    }

    /// Whether [`Field::adjusted`] turns anything: there are tropisms.
    #[inline]
    pub(super) fn acts(&self) -> bool {
        !self.tropisms.is_empty()
    }

    /// Before a step forward: the frame with the heading turned towards
    /// the tropisms' sum, and the up vector by the torques.
    pub(super) fn adjusted(
        &self,
        mut head: DVec3,
        mut left: DVec3,
        mut up: DVec3,
    ) -> (DVec3, DVec3, DVec3) {
        if self.acts() {
            self.adjust_by_all(&mut head, &mut left, &mut up);
        }
        (head, left, up)
    }

    fn adjust_by_all(&self, head: &mut DVec3, left: &mut DVec3, up: &mut DVec3) {
        let mut desired = self.global;
        let mut found = false;
        for (i, t) in self.tropisms.iter().enumerate() {
            if t.torque {
                continue;
            }
            found = true;
            let sin = t.angle.sin();
            if sin != 0.0 {
                let mut v = head.cross(t.direction);
                let mut len = v.length();
                if len < EPSILON {
                    v = *left;
                    len = 1.0;
                }
                desired += t.direction.cross(v) * (self.elasticity[i] * sin / len);
            }
        }
        if found {
            let axis = head.cross(desired);
            let len = axis.length();
            if len >= EPSILON {
                // A turn by |H x desired| radians, at most one (lpfg divides
                // by the clamped length, so a long axis is not a unit one).
                let len = len.min(1.0);
                let q = quat(-len * 0.5, axis / len);
                *head = rotate_by(*head, q);
                *up = rotate_by(*up, q);
                *left = up.cross(*head);
            }
        }
        let twist = self.twist.length();
        if twist > 0.0 {
            let v = head.cross(self.twist);
            if v.length() > EPSILON {
                let wanted = v.cross(*head).normalize() * twist;
                *up = rotate_to(*up, wanted);
                *left = up.cross(*head);
            }
        }
    }
}

/// After a step forward: the frame with the heading bent by the simple
/// tropism, once towards up and once towards left.
pub(super) fn bent(
    s: &SimpleTropism,
    mut head: DVec3,
    mut left: DVec3,
    mut up: DVec3,
) -> (DVec3, DVec3, DVec3) {
    if s.elasticity == 0.0 {
        return (head, left, up);
    }
    for other in [&mut up, &mut left] {
        let c = s.elasticity * s.direction.dot(*other);
        let r = (1.0 - c * c).sqrt();
        let h = head * r + *other * c;
        *other = *other * r - head * c;
        head = h;
    }
    (head, left, up)
}

/// The quaternion `(cos a, sin a * axis)`.
fn quat(a: f64, axis: DVec3) -> [f64; 4] {
    let (s, c) = a.sin_cos();
    [c, axis.x * s, axis.y * s, axis.z * s]
}

/// Hamilton's product.
fn mul(a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
    [
        a[0] * b[0] - (a[1] * b[1] + a[2] * b[2] + a[3] * b[3]),
        a[0] * b[1] + b[0] * a[1] + a[2] * b[3] - a[3] * b[2],
        a[0] * b[2] + b[0] * a[2] + a[3] * b[1] - a[1] * b[3],
        a[0] * b[3] + b[0] * a[3] + a[1] * b[2] - a[2] * b[1],
    ]
}

/// `v` turned by `q` as lpfg turns vectors: `q⁻¹ v q`, with the inverse of
/// a quaternion that need not be a unit one.
fn rotate_by(v: DVec3, q: [f64; 4]) -> DVec3 {
    let n = q.iter().map(|x| x * x).sum::<f64>();
    let inv = [q[0] / n, -q[1] / n, -q[2] / n, -q[3] / n];
    let r = mul(mul(inv, [0.0, v.x, v.y, v.z]), q);
    DVec3::new(r[1], r[2], r[3])
}

/// lpfg's `RotateTo`: `v` turned about `v x to` by a quaternion whose
/// half angle is half the cross product's length (at most 1, and 1 when
/// the two point apart).
fn rotate_to(v: DVec3, to: DVec3) -> DVec3 {
    let axis = v.cross(to);
    let mut len = axis.length();
    if v.dot(to) < 0.0 || len > 1.0 {
        len = 1.0;
    }
    if len == 0.0 {
        return v;
    }
    let a = len * 0.5;
    let s = a.sin() / len;
    rotate_by(v, [a.cos(), axis.x * s, axis.y * s, axis.z * s])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn view_file_lines_are_read_as_lpfg_reads_them() {
        let t = Tropism::parse(" T: 0 -2 0 A: 90 I: 0.5 E: 0.2 S: 0.05", false).unwrap();
        assert_eq!(t.direction, DVec3::new(0.0, -1.0, 0.0));
        assert_eq!(
            (t.angle, t.elasticity, t.step),
            (90f64.to_radians(), 0.2, 0.05)
        );
        assert!(Tropism::parse("T: 0 0 0", false).is_none());
        assert!(Tropism::parse("T: 0 1 0 A: 10", true).is_none());
        assert!(Tropism::parse("T: 0 1 0 A: 200", false).is_none());
        assert!(Tropism::parse("T: 0 1", false).is_none());
        let s = SimpleTropism::parse(" 0 -1 0, 0.3").unwrap();
        assert_eq!((s.direction, s.elasticity), (DVec3::NEG_Y, 0.3));
        assert!(SimpleTropism::parse("0 -1 0 0.3").is_none());
    }

    #[test]
    fn a_unit_quaternion_turns_by_minus_its_angle() {
        // q = (cos a, sin a n) gives q⁻¹ v q: a turn by -2a about n, so
        // x about z by -90 degrees is -y.
        let q = quat(std::f64::consts::FRAC_PI_4, DVec3::Z);
        let v = rotate_by(DVec3::X, q);
        assert!((v - DVec3::NEG_Y).length() < 1e-12, "{v}");
    }
}
