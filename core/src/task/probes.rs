//! The counted probes of a [`Task`]: one per scene view (generic integrand, hemisphere, image
//! plane, environment-map sequence, medium). Each call counts its samples, rays or fetches on the
//! task before it reaches the scene.

use super::*;

/// Counted access to the generic integrand of a task: every evaluation is one sample.
pub struct IntegrandProbe<'a> {
    pub(super) f: &'a dyn crate::integrand::Integrand,
    pub(super) task: &'a Task<'a>,
}

impl IntegrandProbe<'_> {
    /// The domain (free).
    pub fn domain(&self) -> crate::integrand::Domain {
        self.f.domain()
    }
    /// `f(x)`: one sample.
    pub fn eval(&self, x: &[f64]) -> f64 {
        self.task.count(|c| c.samples += 1);
        self.f.eval(x)
    }
}

/// Counted access to a hemispherical integral.
pub struct HemisphereProbe<'a> {
    pub(super) scene: &'a dyn HemisphereScene,
    pub(super) task: &'a Task<'a>,
    pub(super) point: ShadingPoint,
    pub(super) brdf: crate::phong_at::PhongAt,
}

impl HemisphereProbe<'_> {
    /// The shading point (geometry and BRDF are known locally and cost nothing).
    pub fn point(&self) -> &ShadingPoint {
        &self.point
    }
    /// The point's BRDF bound to its view direction and normal (free).
    pub fn brdf(&self) -> &crate::phong_at::PhongAt {
        &self.brdf
    }
    /// Counts `n` radiance-cache operations on this integral ([`Task::count_cache_ops`]).
    pub fn count_cache_ops(&self, n: u64) {
        self.task.count_cache_ops(n);
    }
    /// The scene's area lights (geometry only, free); sample them, then evaluate the sampled
    /// direction with [`HemisphereProbe::integrand`], which counts it.
    pub fn lights(&self) -> &[crate::lighting::RectLight] {
        self.scene.lights()
    }
    /// The integrand `L_in(w_i) f(w_i, w_o) cos(theta_i)`: one sample and one ray. Zero below the
    /// horizon (still one sample: the estimator drew it).
    pub fn integrand(&self, wi: Vec3) -> Rgb {
        self.integrand_with_brdf(wi, self.brdf.eval(wi))
    }
    /// [`HemisphereProbe::integrand`] given the BRDF value `f = f(w_i, w_o)` at `wi` (from
    /// [`crate::phong_at::PhongAt::eval_pdf`], which shares its work with the density): the same
    /// count and bits.
    pub fn integrand_with_brdf(&self, wi: Vec3, f: Rgb) -> Rgb {
        self.task.count(|c| c.samples += 1);
        let cos = wi.dot(self.point.normal);
        if cos <= 0.0 {
            return Rgb::ZERO;
        }
        self.task.count(|c| c.rays += 1);
        self.scene.incident(self.task.integral, wi) * f * cos
    }
}

/// Counted access to one pixel of an image-plane scene (paper 003 §4): every pixel sample counts
/// one sample (the papers' spp) and the rays it traced.
pub struct ImageProbe<'a> {
    pub(super) scene: &'a dyn ImagePlaneScene,
    pub(super) task: &'a Task<'a>,
}

impl ImageProbe<'_> {
    /// One pixel sample at footprint position `(u, v)` in `[0, 1)^2`.
    pub fn sample(&self, u: f64, v: f64, rng: &mut crate::rng::StreamRng) -> Rgb {
        let (value, rays) = self.scene.pixel_sample(self.task.integral, u, v, rng);
        self.task.count(|c| {
            c.samples += 1;
            c.rays += rays;
        });
        value
    }
    /// Records a diagnostic on this pixel's task ([`Task::note`]).
    pub fn note(&self, name: &'static str, value: f64) {
        self.task.note(name, value);
    }
    /// The pixel's index in the image (row-major, the task's integral).
    pub fn pixel(&self) -> usize {
        self.task.integral
    }
    /// The image's size in pixels, `(width, height)` (geometry, free).
    pub fn resolution(&self) -> (usize, usize) {
        self.task.bed.resolution()
    }
    /// Counts `n` target evaluations on this pixel ([`Task::count_target_evals`]).
    pub fn count_target_evals(&self, n: u64) {
        self.task.count_target_evals(n);
    }
}

/// Counted access to one frame of one pixel of an environment sequence (paper 004). Every
/// evaluation of the product `L_i f cos` counts one sample and one target evaluation, and every
/// visibility test one ray.
pub struct EnvProbe<'a> {
    pub(super) scene: &'a dyn EnvSequenceScene,
    pub(super) task: &'a Task<'a>,
    pub(super) pixel: usize,
    pub(super) frame: usize,
    pub(super) point: ShadingPoint,
    pub(super) env: EnvFrame<'a>,
}

impl EnvProbe<'_> {
    /// The shading point (geometry and BRDF are known locally and cost nothing).
    pub fn point(&self) -> &ShadingPoint {
        &self.point
    }
    /// This integral's frame (0-based).
    pub fn frame(&self) -> usize {
        self.frame
    }
    /// The pixel.
    pub fn pixel(&self) -> usize {
        self.pixel
    }
    /// The quantity asked for (`L_r` or `L_ns`).
    pub fn quantity(&self) -> EnvQuantity {
        self.scene.quantity()
    }
    /// The unnormalised product `p~_n(w) = L_n(w) f(w, w_o) cos(theta)` of this frame per channel,
    /// without visibility (paper 004 Eq. 2): one sample and one target evaluation.
    pub fn target(&self, wi: Vec3) -> Rgb {
        self.eval(&self.env, wi)
    }
    /// The same product for another frame of the sequence (bridges between frames need
    /// `p~_{n-1}` at new points, paper 004 Eq. 11): one sample and one target evaluation,
    /// counted on this integral.
    pub fn target_in_frame(&self, frame: usize, wi: Vec3) -> Rgb {
        self.eval(&self.scene.environment(frame), wi)
    }
    fn eval(&self, env: &EnvFrame<'_>, wi: Vec3) -> Rgb {
        // A direction below the horizon is still an evaluation the sampler asked for (its value,
        // zero, weights or rejects it).
        self.task.count(|c| {
            c.samples += 1;
            c.target_evals += 1;
        });
        let p = &self.point;
        let cos = wi.dot(p.normal);
        if cos <= 0.0 {
            return Rgb::ZERO;
        }
        env.radiance(wi) * p.brdf.eval(wi, p.wo, p.normal) * cos
    }
    /// This frame's environment (radiance and sampler), for MH proposals.
    pub fn environment_frame(&self) -> EnvFrame<'_> {
        self.env
    }
    /// Records a diagnostic on this integral's task ([`Task::note`]).
    pub fn note(&self, name: &'static str, value: f64) {
        self.task.note(name, value);
    }
    /// Visibility of `wi` from the shading point: one shadow ray.
    pub fn visible(&self, wi: Vec3) -> bool {
        self.task.count(|c| {
            c.rays += 1;
            c.shadow_rays += 1;
        });
        self.scene.visible(self.pixel, wi)
    }
    /// A direction from this frame's environment-map sampler (density proportional to the
    /// channel-mean radiance per solid angle) with its density.
    pub fn sample_environment<R: Rng + ?Sized>(&self, rng: &mut R) -> DirectionSample {
        self.env.sample(rng)
    }
    /// The density of [`EnvProbe::sample_environment`] at `wi`.
    pub fn environment_pdf(&self, wi: Vec3) -> f64 {
        self.env.pdf(wi)
    }
    /// The environment-map density of another frame.
    pub fn environment_pdf_in_frame(&self, frame: usize, wi: Vec3) -> f64 {
        self.scene.environment(frame).pdf(wi)
    }
}

/// Counted access to a participating medium (paper 002): every extinction evaluation is one fetch,
/// every approximate (cheap) evaluation one cheap fetch, every path or transmittance ray started
/// one sample and one ray. Albedo, bounds and environment radiance come with the fetch or are
/// scene constants and cost nothing extra.
pub struct MediumProbe<'a> {
    pub(super) scene: &'a dyn MediumScene,
    pub(super) task: &'a Task<'a>,
    pub(super) ray: MediumRay,
}

impl MediumProbe<'_> {
    /// The ray of this integral.
    #[inline]
    pub fn ray(&self) -> &MediumRay {
        &self.ray
    }
    /// Starts one sample (a transmittance ray or a particle path): one sample and one ray.
    #[inline]
    pub fn start_sample(&self) {
        self.task.count(|c| {
            c.samples += 1;
            c.rays += 1;
        });
    }
    /// Counts one more ray within the current sample (a shadow ray towards a light).
    pub fn shadow_ray(&self) {
        self.task.count(|c| {
            c.rays += 1;
            c.shadow_rays += 1;
        });
    }
    /// Counts `n` radiance-cache operations on this integral ([`Task::count_cache_ops`]).
    pub fn count_cache_ops(&self, n: u64) {
        self.task.count_cache_ops(n);
    }
    /// Counts one more free-flight segment of the current path (the ray leaving a scattering
    /// vertex): a renderer traces it like any other ray, so `rays` counts segments, not paths.
    #[inline]
    pub fn scattered_ray(&self) {
        self.task.count(|c| {
            c.rays += 1;
            c.free_flights += 1;
        });
    }
    /// Real extinction at `p`: one fetch.
    #[inline]
    pub fn sigma_t(&self, p: Vec3) -> f64 {
        self.task.count(|c| c.fetches += 1);
        self.scene.sigma_t(p)
    }
    /// The approximate extinction at `p`: one cheap fetch when the scene has one, else one full
    /// fetch of the real extinction.
    pub fn sigma_approx(&self, p: Vec3) -> f64 {
        match self.scene.sigma_approx(p) {
            Some(v) => {
                self.task.count(|c| c.cheap_fetches += 1);
                v
            }
            None => self.sigma_t(p),
        }
    }
    /// The majorant the scene declares.
    #[inline]
    pub fn majorant(&self) -> f64 {
        self.scene.majorant()
    }
    /// The albedo.
    #[inline]
    pub fn albedo(&self) -> f64 {
        self.scene.albedo()
    }
    /// Clips a ray to the medium's bounding volume (geometry only: free).
    #[inline]
    pub fn clip(&self, origin: Vec3, dir: Vec3) -> Option<(f64, f64)> {
        self.scene.clip(origin, dir)
    }
    /// Environment radiance from direction `w` leaving the scene (free: analytic lighting).
    #[inline]
    pub fn environment(&self, w: Vec3) -> Rgb {
        self.scene.environment(w)
    }
    /// The phase function (a scene constant: free).
    #[inline]
    pub fn phase(&self) -> crate::phase::Phase {
        self.scene.phase()
    }
    /// Records a diagnostic on this integral's task ([`Task::note`]).
    pub fn note(&self, name: &'static str, value: f64) {
        self.task.note(name, value);
    }
    /// True while this integral's budget is not spent ([`Task::more`]).
    #[inline]
    pub fn more(&self) -> bool {
        self.task.more()
    }
}
