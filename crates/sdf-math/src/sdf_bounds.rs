//! The bounds of an [`Sdf`]: spheres, boxes and half-spaces with the field contract
//! (stronger than containment) that lets a ray skip a shape it never comes near.

use glam::Vec3;

use crate::Sdf;
use crate::bound::{Aabb, HalfSpace};
use crate::sdf::{rotate, usable_factor};

impl Sdf {
    /// A conservative bounding sphere `(centre, radius)`, or `None` when the shape is
    /// unbounded (a plane, an intersection of unbounded shapes).
    ///
    /// Contract, stronger than containment: for every `p`,
    /// `distance(p) >= |p - centre| - radius`. So a ray that misses the sphere misses the
    /// shape, and outside it the sphere is itself a safe step. Smooth unions widen the
    /// sphere by `k` per blended child, the most each fold can undercut the hard minimum.
    ///
    /// The centre and radius are always finite: where extreme parameters overflow, the
    /// answer is `None`, which is always conservative.
    pub fn bounding_sphere(&self) -> Option<(Vec3, f32)> {
        self.bounding_sphere_unchecked()
            .filter(|(centre, radius)| centre.is_finite() && radius.is_finite())
    }

    fn bounding_sphere_unchecked(&self) -> Option<(Vec3, f32)> {
        const NOTHING: Option<(Vec3, f32)> = Some((Vec3::ZERO, 0.0));
        match self {
            Self::Primitive(shape) => shape.bounding_sphere(),
            Self::Union(children) => merge_all(children),
            Self::SmoothUnion { k, children } => {
                let (centre, radius) = merge_all(children)?;
                let blends = children.len().saturating_sub(1) as f32;
                Some((centre, radius + blends * k.max(0.0)))
            }
            // max(f0, ...) >= f_i for every i, so any bounded child's sphere will do.
            Self::Intersection(children) | Self::SmoothIntersection { children, .. } => children
                .iter()
                .filter_map(Self::bounding_sphere)
                .min_by(|x, y| x.1.total_cmp(&y.1)),
            // Every fold is >= its left argument, so the result is >= f0.
            Self::Difference(children) | Self::SmoothDifference { children, .. } => {
                match children.first() {
                    None => NOTHING,
                    Some(first) => first.bounding_sphere(),
                }
            }
            Self::Translate { offset, child } => {
                let (centre, radius) = child.bounding_sphere()?;
                Some((centre + *offset, radius))
            }
            Self::Rotate { rotation, child } => {
                let (centre, radius) = child.bounding_sphere()?;
                Some((rotate(*rotation, centre), radius))
            }
            Self::Scale { factor, child } => {
                if usable_factor(*factor) {
                    let (centre, radius) = child.bounding_sphere()?;
                    Some((centre * *factor, radius * factor.abs()))
                } else {
                    NOTHING
                }
            }
        }
    }
}

impl Sdf {
    /// A conservative axis-aligned bounding box, or `None` when the shape is unbounded.
    ///
    /// Contract, as for [`Sdf::bounding_sphere`] stronger than containment: for every `p`
    /// outside the box, `distance(p) >=` the Euclidean distance from `p` to the box. So a
    /// ray that stays farther from the box than the hit threshold can never hit the shape
    /// ([`Aabb::hit_interval`]), and outside the box its distance is a safe step.
    ///
    /// Tighter than the sphere for flat and long shapes (a wall's sphere holds the whole
    /// room; its box is the wall). Rotated children get the box around their rotated box,
    /// which may be up to sqrt(3) times larger. Always finite, or `None`.
    pub fn bounding_box(&self) -> Option<Aabb> {
        self.bounding_box_unchecked().filter(Aabb::is_finite)
    }

    fn bounding_box_unchecked(&self) -> Option<Aabb> {
        const NOTHING: Option<Aabb> = Some(Aabb {
            min: Vec3::ZERO,
            max: Vec3::ZERO,
        });
        match self {
            Self::Primitive(shape) => shape.bounding_box(),
            Self::Union(children) => union_boxes(children),
            Self::SmoothUnion { k, children } => {
                let merged = union_boxes(children)?;
                let blends = children.len().saturating_sub(1) as f32;
                Some(merged.inflate(blends * k.max(0.0)))
            }
            // max(f0, ...) >= f_i for every i: any bounded child's box will do; the
            // smallest by its diagonal.
            Self::Intersection(children) | Self::SmoothIntersection { children, .. } => children
                .iter()
                .filter_map(Self::bounding_box)
                .min_by(|x, y| {
                    let size = |b: &Aabb| b.half_extents().length_squared();
                    size(x).total_cmp(&size(y))
                }),
            Self::Difference(children) | Self::SmoothDifference { children, .. } => {
                match children.first() {
                    None => NOTHING,
                    Some(first) => first.bounding_box(),
                }
            }
            Self::Translate { offset, child } => {
                let b = child.bounding_box()?;
                Some(Aabb {
                    min: b.min + *offset,
                    max: b.max + *offset,
                })
            }
            // The rotated box's own box (centre rotated, half extents through |R|), or the
            // box around the child's bounding sphere, which rotation does not grow (a
            // sphere's field is at least the distance to that ball, so to its box):
            // whichever is smaller.
            Self::Rotate { rotation, child } => {
                let b = child.bounding_box()?;
                let h = b.half_extents();
                let [x, y, z] = [Vec3::X, Vec3::Y, Vec3::Z].map(|e| rotate(*rotation, e).abs());
                let half = x * h.x + y * h.y + z * h.z;
                let turned = Aabb::from_center(rotate(*rotation, b.center()), half);
                let volume = |b: &Aabb| b.half_extents().element_product();
                match child.bounding_sphere() {
                    Some((c, r)) => {
                        let ball = Aabb::from_center(rotate(*rotation, c), Vec3::splat(r));
                        Some(if volume(&ball) < volume(&turned) {
                            ball
                        } else {
                            turned
                        })
                    }
                    None => Some(turned),
                }
            }
            Self::Scale { factor, child } => {
                if usable_factor(*factor) {
                    let b = child.bounding_box()?;
                    Some(Aabb::from_center(
                        b.center() * *factor,
                        b.half_extents() * factor.abs(),
                    ))
                } else {
                    NOTHING
                }
            }
        }
    }

    /// A half-space the field never undercuts, or `None`: for every `p`,
    /// `distance(p) >= dot(p, normal) - height` (everywhere, inside too). Planes and what
    /// is cut from them (intersections, differences) have one; a tracer clips rays
    /// against it exactly ([`HalfSpace::hit_interval`]), which is what makes rays that
    /// leave a floor, or stay above it, cost nothing for the floor.
    pub fn bounding_half_space(&self) -> Option<HalfSpace> {
        self.bounding_half_space_unchecked()
            .filter(|h| h.normal.is_finite() && h.height.is_finite())
    }

    fn bounding_half_space_unchecked(&self) -> Option<HalfSpace> {
        match self {
            Self::Primitive(shape) => shape.bounding_half_space(),
            Self::Intersection(children) | Self::SmoothIntersection { children, .. } => {
                children.iter().find_map(Self::bounding_half_space)
            }
            Self::Difference(children) | Self::SmoothDifference { children, .. } => {
                children.first()?.bounding_half_space()
            }
            Self::Translate { offset, child } => {
                let h = child.bounding_half_space()?;
                Some(HalfSpace {
                    normal: h.normal,
                    height: h.height + offset.dot(h.normal),
                })
            }
            Self::Rotate { rotation, child } => {
                let h = child.bounding_half_space()?;
                Some(HalfSpace {
                    normal: rotate(*rotation, h.normal),
                    height: h.height,
                })
            }
            // |c| f(p / c) >= |c| (dot(p / c, n) - h) = dot(p, sign(c) n) - |c| h.
            Self::Scale { factor, child } if usable_factor(*factor) => {
                let h = child.bounding_half_space()?;
                Some(HalfSpace {
                    normal: h.normal * factor.signum(),
                    height: h.height * factor.abs(),
                })
            }
            // A union reaches wherever any of its children does, so no one child's
            // half-space holds it; a collapsed scale is nothing and needs none.
            Self::Union(_) | Self::SmoothUnion { .. } | Self::Scale { .. } => None,
        }
    }
}

/// Union of the children's boxes: an empty box for no children (the empty shape), `None`
/// if any child is unbounded.
fn union_boxes(children: &[Sdf]) -> Option<Aabb> {
    let mut boxes = children.iter().map(Sdf::bounding_box);
    let Some(first) = boxes.next() else {
        return Some(Aabb {
            min: Vec3::ZERO,
            max: Vec3::ZERO,
        });
    };
    boxes.try_fold(first?, |acc, b| Some(acc.union(&b?)))
}

/// The smallest sphere holding both spheres.
fn merge(x: (Vec3, f32), y: (Vec3, f32)) -> (Vec3, f32) {
    let ((cx, rx), (cy, ry)) = (x, y);
    let gap = (cy - cx).length();
    if gap + ry <= rx {
        return x;
    }
    if gap + rx <= ry {
        return y;
    }
    let radius = (gap + rx + ry) * 0.5;
    // gap > |rx - ry| >= 0 here, so the division is safe.
    let centre = cx + (cy - cx) * ((radius - rx) / gap);
    (centre, radius)
}

/// Merged sphere of all children: `Some((0, 0))` for no children (the empty shape), `None`
/// if any child is unbounded.
fn merge_all(children: &[Sdf]) -> Option<(Vec3, f32)> {
    let mut spheres = children.iter().map(Sdf::bounding_sphere);
    let Some(first) = spheres.next() else {
        return Some((Vec3::ZERO, 0.0));
    };
    spheres.try_fold(first?, |acc, s| Some(merge(acc, s?)))
}
