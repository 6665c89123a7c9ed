//! The transform that places a mesh (§6.6: "a full transformation matrix for each mesh",
//! before a Boolean operation), written as steps applied in the order given, separated by
//! `;` — after `@` in a mesh name ([`super::spec::Placed`]) or in `--transform-b`:
//!
//! - `translate X Y Z`
//! - `rotate x|y|z DEGREES` or `rotate AX AY AZ DEGREES` (about an axis through the origin)
//! - `scale S` or `scale SX SY SZ`
//! - `matrix M00 M01 M02 M03 M10 … M23` (the upper 3×4 rows of an affine matrix)
//!
//! e.g. `--transform-b "rotate y 10; translate 0.5 0 0"`. A transform that mirrors
//! (negative determinant) also reverses every face, so the solid stays outward-facing.

use glam::{DAffine3, DMat3, DVec3};

use super::Mesh;

/// A parsed transform.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform(pub DAffine3);

impl Default for Transform {
    fn default() -> Transform {
        Transform(DAffine3::IDENTITY)
    }
}

impl Transform {
    /// Parses the step list described in the module docs.
    pub fn parse(text: &str) -> Result<Transform, String> {
        let mut m = DAffine3::IDENTITY;
        for step in text.split(';').map(str::trim).filter(|s| !s.is_empty()) {
            let mut words = step.split_whitespace();
            let name = words.next().unwrap_or_default();
            let rest: Vec<&str> = words.collect();
            let nums = |want: &[usize]| -> Result<Vec<f64>, String> {
                let v: Result<Vec<f64>, _> = rest.iter().map(|w| w.parse::<f64>()).collect();
                let v = v.map_err(|_| format!("'{step}': expected numbers"))?;
                if !want.contains(&v.len()) || v.iter().any(|x| !x.is_finite()) {
                    return Err(format!(
                        "'{step}': expected {} finite number(s)",
                        want.iter().map(usize::to_string).collect::<Vec<_>>().join(" or ")
                    ));
                }
                Ok(v)
            };
            let next = match name {
                "translate" => {
                    let v = nums(&[3])?;
                    DAffine3::from_translation(DVec3::new(v[0], v[1], v[2]))
                }
                "scale" => {
                    let v = nums(&[1, 3])?;
                    let s = if v.len() == 1 { DVec3::splat(v[0]) } else { DVec3::new(v[0], v[1], v[2]) };
                    if s.cmpeq(DVec3::ZERO).any() {
                        return Err(format!("'{step}': a zero scale flattens the solid"));
                    }
                    DAffine3::from_scale(s)
                }
                "rotate" => {
                    let (axis, degrees) = match rest.as_slice() {
                        [a @ ("x" | "y" | "z"), d] => {
                            let axis = match *a {
                                "x" => DVec3::X,
                                "y" => DVec3::Y,
                                _ => DVec3::Z,
                            };
                            (axis, d.parse::<f64>().map_err(|_| format!("'{step}': bad angle"))?)
                        }
                        _ => {
                            let v = nums(&[4])?;
                            (DVec3::new(v[0], v[1], v[2]), v[3])
                        }
                    };
                    let axis = axis.try_normalize().ok_or_else(|| format!("'{step}': zero axis"))?;
                    if !degrees.is_finite() {
                        return Err(format!("'{step}': bad angle"));
                    }
                    DAffine3::from_axis_angle(axis, degrees.to_radians())
                }
                "matrix" => {
                    let v = nums(&[12])?;
                    let cols = [0, 1, 2].map(|c| DVec3::new(v[c], v[4 + c], v[8 + c]));
                    let m3 = DMat3::from_cols(cols[0], cols[1], cols[2]);
                    if m3.determinant() == 0.0 {
                        return Err(format!("'{step}': the matrix is singular"));
                    }
                    DAffine3 { matrix3: m3, translation: DVec3::new(v[3], v[7], v[11]) }
                }
                _ => {
                    return Err(format!(
                        "unknown transform step '{step}' (expected translate, rotate, scale or matrix)"
                    ));
                }
            };
            m = next * m;
        }
        Ok(Transform(m))
    }

    pub fn is_identity(&self) -> bool {
        self.0 == DAffine3::IDENTITY
    }

    /// `mesh` with every position transformed (faces reversed when the transform mirrors).
    pub fn apply(&self, mesh: &Mesh) -> crate::mesh::Result<Mesh> {
        if self.is_identity() {
            return Ok(mesh.clone());
        }
        let moved = mesh.map_positions(|p| self.0.transform_point3(p))?;
        if self.0.matrix3.determinant() >= 0.0 {
            return Ok(moved);
        }
        let faces = moved.faces().map(|f| f.iter().rev().copied().collect()).collect();
        Mesh::new(moved.positions().to_vec(), faces)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn steps_apply_in_order() {
        let t = Transform::parse("rotate z 90; translate 1 0 0").unwrap();
        let p = t.0.transform_point3(DVec3::X);
        assert!((p - DVec3::new(1.0, 1.0, 0.0)).length() < 1e-15, "{p}");
        let s = Transform::parse("scale 2; scale 1 1 -1").unwrap();
        assert_eq!(s.0.transform_point3(DVec3::ONE), DVec3::new(2.0, 2.0, -2.0));
        let m = Transform::parse("matrix 1 0 0 5  0 1 0 6  0 0 1 7").unwrap();
        assert_eq!(m.0.transform_point3(DVec3::ZERO), DVec3::new(5.0, 6.0, 7.0));
        assert!(Transform::parse("").unwrap().is_identity());
        for bad in ["rotate q 10", "translate 1 2", "scale 0", "shear 1", "translate 1 nan 2"] {
            assert!(Transform::parse(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn mirroring_keeps_the_solid_outward() {
        let cube = crate::mesh::procedural::cube();
        let m = Transform::parse("scale -1 1 1").unwrap().apply(&cube).unwrap();
        let v = crate::mesh::covering::Covering::new(&m).volume();
        assert!((v - 8.0).abs() < 1e-12, "{v}");
    }
}
