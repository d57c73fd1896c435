//! Image vortices for a symmetry plane and/or a ground plane.
//!
//! Reflecting a filament A→B of strength Γ through a plane gives A*→B* with strength −Γ
//! (a reflection reverses orientation), which cancels the normal velocity on the plane. With two
//! perpendicular planes the doubly reflected copy carries +Γ. The unknowns stay those of the
//! meshed half; the cost of every induction grows ×2 (×4 with both planes).

use crate::biot_savart::Filaments;
use crate::error::{Result, UvlmError};
use serde::{Deserialize, Serialize};

/// A mirror plane through `point` with normal `normal` (need not be unit length).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ImagePlane {
    /// A point of the plane, m.
    pub point: [f64; 3],
    /// Plane normal (any length > 0).
    pub normal: [f64; 3],
}

impl ImagePlane {
    /// Symmetry plane through the origin with the given normal (e.g. `[0, 1, 0]` for y = 0).
    pub fn through_origin(normal: [f64; 3]) -> Self {
        Self { point: [0.0; 3], normal }
    }

    /// Reflect a point.
    #[inline]
    pub fn reflect_point(&self, p: [f64; 3], n: [f64; 3]) -> [f64; 3] {
        let d = (p[0] - self.point[0]) * n[0] + (p[1] - self.point[1]) * n[1] + (p[2] - self.point[2]) * n[2];
        [p[0] - 2.0 * d * n[0], p[1] - 2.0 * d * n[1], p[2] - 2.0 * d * n[2]]
    }

    /// Reflect a direction.
    #[inline]
    pub fn reflect_dir(&self, v: [f64; 3], n: [f64; 3]) -> [f64; 3] {
        let d = v[0] * n[0] + v[1] * n[1] + v[2] * n[2];
        [v[0] - 2.0 * d * n[0], v[1] - 2.0 * d * n[1], v[2] - 2.0 * d * n[2]]
    }

    /// Unit normal.
    pub fn unit_normal(&self) -> [f64; 3] {
        let l = (self.normal[0].powi(2) + self.normal[1].powi(2) + self.normal[2].powi(2)).sqrt();
        [self.normal[0] / l, self.normal[1] / l, self.normal[2] / l]
    }
}

/// Check a set of image planes: at most two, finite, non-zero normals, perpendicular if two.
pub fn validate_planes(planes: &[ImagePlane]) -> Result<()> {
    if planes.len() > 2 {
        return Err(UvlmError::InvalidParameter { field: "images (count)", value: planes.len() as f64 });
    }
    for p in planes {
        let l2 = p.normal.iter().map(|v| v * v).sum::<f64>();
        if !(l2.is_finite() && l2 > 0.0 && p.point.iter().all(|v| v.is_finite())) {
            return Err(UvlmError::InvalidParameter { field: "images.normal", value: l2 });
        }
    }
    if planes.len() == 2 {
        let (a, b) = (planes[0].unit_normal(), planes[1].unit_normal());
        let c = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        if c.abs() > 1e-9 {
            return Err(UvlmError::InvalidParameter { field: "images (planes must be perpendicular), cos", value: c });
        }
    }
    Ok(())
}

/// Signs of the copies made by [`append_images`]: `[1]`, `[1, −1]` or `[1, −1, −1, 1]`.
pub fn copy_signs(n_planes: usize) -> &'static [f64] {
    match n_planes {
        0 => &[1.0],
        1 => &[1.0, -1.0],
        _ => &[1.0, -1.0, -1.0, 1.0],
    }
}

/// Append the image copies of everything currently in `fil` (nodes, segments, legs), in the
/// order of [`copy_signs`]: copy `k` of segment `s` is segment `k·n_seg + s`, likewise legs.
/// Strengths are multiplied by the copy sign; core constants are kept (reflection preserves lengths).
pub fn append_images(fil: &mut Filaments, planes: &[ImagePlane]) {
    let copies: &[&[usize]] = match planes.len() {
        0 => &[],
        1 => &[&[0]],
        _ => &[&[0], &[1], &[0, 1]],
    };
    let (nn, ns, nl) = (fil.n_nodes(), fil.n_segments(), fil.n_legs());
    let mut units = [[0.0; 3]; 2];
    for (u, p) in units.iter_mut().zip(planes) {
        *u = p.unit_normal();
    }
    for (c, list) in copies.iter().enumerate() {
        let sign = copy_signs(planes.len())[c + 1];
        let base = fil.n_nodes() as u32;
        for i in 0..nn {
            let mut p = fil.node(i);
            for &k in list.iter() {
                p = planes[k].reflect_point(p, units[k]);
            }
            fil.push_node(p);
        }
        for s in 0..ns {
            fil.seg_a.push(base + fil.seg_a[s]);
            fil.seg_b.push(base + fil.seg_b[s]);
            fil.seg_g.push(sign * fil.seg_g[s]);
            fil.seg_core2.push(fil.seg_core2[s]);
            fil.seg_cut2.push(fil.seg_cut2[s]);
        }
        for l in 0..nl {
            let mut d = fil.leg_d[l];
            for &k in list.iter() {
                d = planes[k].reflect_dir(d, units[k]);
            }
            fil.leg_a.push(base + fil.leg_a[l]);
            fil.leg_d.push(d);
            fil.leg_g.push(sign * fil.leg_g[l]);
            fil.leg_core2.push(fil.leg_core2[l]);
            fil.leg_cut2.push(fil.leg_cut2[l]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::biot_savart::CoreModel;
    use approx::assert_relative_eq;

    /// The image of a vortex cancels the velocity normal to the plane, everywhere on the plane.
    #[test]
    fn image_cancels_normal_velocity_on_plane() {
        let core = CoreModel::CutOff { radius: 0.0 };
        for plane in [
            ImagePlane::through_origin([0.0, 1.0, 0.0]),
            ImagePlane { point: [0.0, 0.0, -0.7], normal: [0.0, 0.0, 2.0] },
        ] {
            let mut fil = Filaments::default();
            let a = fil.push_node([0.1, 0.3, 0.2]);
            let b = fil.push_node([0.4, 1.3, 0.25]);
            fil.push_segment(a, b, 1.7, &core);
            fil.push_leg(b, [0.8, 0.0, 0.6], -0.4, &core, 1.0);
            append_images(&mut fil, &[plane]);
            let n = plane.unit_normal();
            for p in [[0.3, 0.0, 0.1], [-2.0, 0.0, 1.5]] {
                let p = if n[1] != 0.0 { p } else { [p[0], p[2], -0.7] };
                let u = fil.velocity_at(p);
                assert_relative_eq!(u[0] * n[0] + u[1] * n[1] + u[2] * n[2], 0.0, epsilon = 1e-14);
            }
        }
    }

    #[test]
    fn two_planes_must_be_perpendicular() {
        let a = ImagePlane::through_origin([0.0, 1.0, 0.0]);
        let b = ImagePlane::through_origin([0.0, 1.0, 1.0]);
        assert!(validate_planes(&[a, b]).is_err());
        assert!(validate_planes(&[a, ImagePlane::through_origin([0.0, 0.0, 1.0])]).is_ok());
        assert!(validate_planes(&[a, a, a]).is_err());
    }
}
