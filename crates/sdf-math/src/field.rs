//! The one trait the tracer and the normal estimators need.

use glam::Vec3;

/// Anything the sphere tracer can march: a distance bound and its Lipschitz constant.
///
/// Contract: for all finite `p`, `q`, `|distance(p) - distance(q)| <= lipschitz() * |p - q|`.
/// That is all sphere tracing needs (Hart 1996, "Sphere tracing: a geometric method for the
/// antialiased ray tracing of implicit surfaces"): a step of `distance(p) / lipschitz()`
/// cannot cross the zero set. Negative values mean inside.
pub trait DistanceField {
    /// Signed distance (or a Lipschitz bound of it) at `p`; negative inside.
    fn distance(&self, p: Vec3) -> f32;
    /// Lipschitz bound L: |f(p) - f(q)| <= L |p - q|. The tracer divides steps by it.
    fn lipschitz(&self) -> f32;
}

impl<F: DistanceField + ?Sized> DistanceField for &F {
    #[inline]
    fn distance(&self, p: Vec3) -> f32 {
        (**self).distance(p)
    }

    #[inline]
    fn lipschitz(&self) -> f32 {
        (**self).lipschitz()
    }
}
