//! `bed.md`: an exported test bed described for any renderer (pbrt included): camera, the
//! integral of each pixel, materials, lighting, and how the Mitsuba scene expresses them.

use super::sky;
use crate::testbeds::gradient_box::BoxSetup;
use mcbench_core::brdf::Phong;
use mcbench_core::lighting::Gradient;
use mcbench_core::phase::Phase;

fn rgb(v: [f64; 3]) -> String {
    format!("({}, {}, {})", v[0], v[1], v[2])
}

fn sky_text(g: &Gradient, clamped: bool) -> String {
    let clamp = if clamped {
        "clamped at zero per channel over the whole sphere: `L(w) = max(0, c0 + c1 w_z + c2 w_x)`"
    } else {
        "`L(w) = c0 + c1 w_z + c2 w_x` (positive over the upper hemisphere, the only part a point of \
         the plane sees; the bitmap holds `max(0, .)`, the same there)"
    };
    format!(
        "## Lighting\n\nAn environment (infinitely distant, no other light) of radiance per channel \
         arriving from unit direction `w` (pointing away from the scene, world +z up), {clamp}, with\n\
         `c0 = {}`, `c1 = {}`, `c2 = {}`.\n\n\
         In `scene.xml` it is Mitsuba's `envmap` over `sky.pfm`, a {}x{} latitude-longitude bitmap of \
         that function: column `i` at longitude `u = (i + 1/2) / W`, row `j` at colatitude \
         `v = j / (H - 1)`, world direction `(sin(pi v) sin(2 pi u), sin(pi v) cos(2 pi u), cos(pi v))` \
         (the emitter's `to_world` turns Mitsuba's +y-up frame to +z up), interpolated bilinearly. The \
         interpolation is the only approximation of the exported scene; its measured error is in the \
         book (exported-beds.md). pbrt-v4's image infinite light uses an equal-area octahedral map: \
         tabulate the same function in that layout.\n\n",
        rgb(g.c0.0),
        rgb(g.c1.0),
        rgb(g.c2.0),
        sky::WIDTH,
        sky::WIDTH / 2
    )
}

const SENSORS: &str = "## The integrals and the sensors\n\nIntegral `k` is pixel (row `k / N`, column \
    `k % N`), row 0 at the top of the image. Each is the radiance arriving at the camera along the \
    ray through the pixel's centre: no pixel footprint, no filter. `scene.xml` has one Mitsuba \
    `radiancemeter` sensor per pixel in that order (sensor `k` is integral `k`; render it with \
    `mi.render(scene, sensor=k, spp=..., seed=...)`, a distinct seed per sensor and repetition), \
    sampling with `independent`; `$spp` and `$max_depth` are parameters of the file (defaults 64 and \
    -1, unlimited).\n\n`reference.npy` holds the reference, float64, shape (N, N, 3), pixel (row, \
    column) as above.\n\n";

/// `bed.md` of `gradient-plane` (a variant with no glossy part).
pub fn gradient_plane(variant: &str, size: usize, brdf: &Phong, sky: &Gradient) -> String {
    let kd = brdf.kd.0;
    let value = |c: usize| kd[c] * (sky.c0[c] + 2.0 / 3.0 * sky.c1[c]);
    format!(
        "# gradient-plane / {variant}, resolution {size}\n\n\
         A Lambertian plane under a gradient sky, seen by a pinhole camera (book: testbeds.md).\n\n\
         ## Camera\n\nA pinhole at `eye = (0, -3, 2)` looking at the origin, world up +z, vertical (and, \
         the image being square, horizontal) field of view 40 degrees, an N x N image with N = {size}. \
         With `f = normalize(target - eye)`, `r = normalize(f x up)`, `u = r x f` and `t = tan(20 deg)`, \
         pixel (row `py`, column `px`) looks along `normalize(f + r x_c t + u y_c t)` with \
         `x_c = 2 (px + 1/2) / N - 1` and `y_c = 1 - 2 (py + 1/2) / N`.\n\n\
         ## Geometry and material\n\nThe plane z = 0 (normal +z), infinite; in `scene.xml` a square of \
         half side 1000 centred on the origin (every pixel's ray hits it within a few units of the \
         origin, and nothing else occludes the sky). Lambertian, reflectance (albedo) \
         `kd = {}`: BRDF `kd / pi`, one bounce (nothing is reflected back onto the plane).\n\n\
         {}{SENSORS}\
         ## Reference\n\nExact: every pixel is `kd (c0 + 2 c1 / 3)` per channel (the `c2 w_x` term \
         integrates to zero against the cosine), `({}, {}, {})`. The reflected radiance is the same at \
         every point and direction, so a camera averaging over pixel footprints would measure the same.\n",
        rgb(kd),
        sky_text(sky, false),
        value(0),
        value(1),
        value(2),
    )
}

/// `bed.md` of `gradient-box`.
pub fn gradient_box(variant: &str, size: usize, sigma_t: f64, setup: &BoxSetup) -> String {
    let phase = match setup.phase {
        Phase::HenyeyGreenstein(g) => format!("Henyey-Greenstein with `g = {g}` (forward scattering for g > 0)"),
        _ => "isotropic".to_string(),
    };
    format!(
        "# gradient-box / {variant}, resolution {size}\n\n\
         A cube of homogeneous participating medium under a gradient sky, seen by an orthographic \
         camera (book: testbeds.md).\n\n\
         ## Camera\n\nOrthographic, looking along +y, an N x N image with N = {size} covering \
         `x, z in [-0.5, 0.5]`: pixel (row `py`, column `px`) is the ray from \
         `(-0.5 + (px + 1/2) / N, -1, 0.5 - (py + 1/2) / N)` along `(0, 1, 0)`.\n\n\
         ## Geometry and medium\n\nThe cube `[-0.5, 0.5]^3` filled with a homogeneous medium: \
         extinction `sigma_t = {sigma_t}`, single-scattering albedo `{}` (scattering \
         `sigma_s = albedo sigma_t`), phase function {phase}, no emission. Its boundary is \
         index-matched (no refraction or reflection: Mitsuba's `null` BSDF); outside is vacuum. \
         Radiance includes every order of scattering (Mitsuba's `volpath`).\n\n\
         {}{SENSORS}\
         ## Reference\n\nThe test bed's reference for this variant and resolution: exact for `furnace` \
         (every path returns `c0`) and `albedo-0` (`exp(-sigma_t) c0`), otherwise a stored Monte Carlo \
         reference of an integrator independent of the estimators, whose per-pixel variance of the \
         mean is `reference_var.npy`.\n",
        setup.albedo,
        sky_text(&setup.background, true),
    )
}
