//! Mitsuba 3 scenes (`scene.xml`, `sky.pfm`) of `gradient-plane` and `gradient-box`.
//!
//! Each pixel is one `radiancemeter` sensor measuring the radiance along the pixel-centre ray of
//! the test bed, which is what the references integrate: sensor `k` of the scene (in file order)
//! is integral `k`, pixel (row `k / width`, column `k % width`). A camera sensor would average the
//! radiance over each pixel's footprint instead (the same on the diffuse plane, whose reflected
//! radiance is the same everywhere; not on the box).

use super::notes;
use super::sky;
use crate::testbeds::gradient_box::GradientBox;
use crate::testbeds::gradient_plane::{variant_brdf, GradientPlaneParams};
use crate::testbeds::pinhole::Pinhole;
use mcbench_core::error::ConfigError;
use mcbench_core::export::SceneFile;
use mcbench_core::lighting::Gradient;
use mcbench_core::math::Vec3;
use mcbench_core::params::{parse, Params};
use mcbench_core::phase::Phase;
use mcbench_core::testbed::TestBed;
use std::fmt::Write;

/// The camera of `gradient-plane`.
pub fn plane_camera() -> Pinhole {
    Pinhole::look_at(Vec3::new(0.0, -3.0, 2.0), Vec3::default(), Vec3::Z, 40.0)
}

/// Half the side of the square that stands in for the infinite plane (every pixel-centre ray
/// hits it within a few units of the origin).
pub const PLANE_HALF_SIDE: f64 = 1000.0;

/// `gradient-plane`: a Lambertian square under the sky, one radiancemeter per pixel.
pub fn gradient_plane(variant: &str, params: &Params) -> Result<Vec<SceneFile>, ConfigError> {
    let size = parse::<GradientPlaneParams>("gradient-plane", params)?.resolution;
    let brdf = variant_brdf(variant)?;
    let kd = brdf.kd.0;
    let cam = plane_camera();
    let rays: Vec<(Vec3, Vec3)> =
        (0..size * size).map(|k| (cam.eye, cam.pixel_direction(k % size, k / size, size))).collect();
    let body = format!(
        "    <integrator type=\"path\">\n        <integer name=\"max_depth\" value=\"$max_depth\"/>\n    </integrator>\n{}\
         \x20   <shape type=\"rectangle\">\n        <transform name=\"to_world\"><scale x=\"{PLANE_HALF_SIDE}\" y=\"{PLANE_HALF_SIDE}\"/></transform>\n\
         \x20       <bsdf type=\"diffuse\"><rgb name=\"reflectance\" value=\"{}, {}, {}\"/></bsdf>\n    </shape>\n",
        emitter(),
        kd[0],
        kd[1],
        kd[2]
    );
    let sky = Gradient::papers();
    Ok(vec![
        SceneFile::new("scene.xml", scene(&body, &rays)),
        SceneFile::new("sky.pfm", sky::pfm(&sky, sky::WIDTH)),
        SceneFile::new("bed.md", notes::gradient_plane(variant, size, &brdf, &sky)),
    ])
}

/// `gradient-box`: a cube of homogeneous medium behind an index-matched (`null`) boundary under
/// the clamped sky, one radiancemeter per pixel looking along +y.
pub fn gradient_box(variant: &str, params: &Params) -> Result<Vec<SceneFile>, ConfigError> {
    let bed = GradientBox::without_reference(variant, params)?;
    let size = bed.resolution().0;
    let sigma_t = bed.setup().sigma_t;
    let phase = match bed.setup().phase {
        Phase::HenyeyGreenstein(g) => format!("<phase type=\"hg\"><float name=\"g\" value=\"{g}\"/></phase>"),
        _ => "<phase type=\"isotropic\"/>".to_string(),
    };
    let rays: Vec<(Vec3, Vec3)> = (0..size * size)
        .map(|k| {
            let r = bed.pixel_ray(k);
            (r.origin, r.dir)
        })
        .collect();
    let body = format!(
        "    <integrator type=\"volpath\">\n        <integer name=\"max_depth\" value=\"$max_depth\"/>\n    </integrator>\n{}\
         \x20   <shape type=\"cube\">\n        <transform name=\"to_world\"><scale value=\"0.5\"/></transform>\n\
         \x20       <bsdf type=\"null\"/>\n        <medium type=\"homogeneous\" name=\"interior\">\n\
         \x20           <float name=\"sigma_t\" value=\"{sigma_t}\"/>\n            <rgb name=\"albedo\" value=\"{a}, {a}, {a}\"/>\n\
         \x20           {phase}\n        </medium>\n    </shape>\n",
        emitter(),
        a = bed.setup().albedo,
    );
    let sky = bed.setup().background;
    Ok(vec![
        SceneFile::new("scene.xml", scene(&body, &rays)),
        SceneFile::new("sky.pfm", sky::pfm(&sky, sky::WIDTH)),
        SceneFile::new("bed.md", notes::gradient_box(variant, size, sigma_t, bed.setup())),
    ])
}

fn emitter() -> String {
    format!(
        "    <emitter type=\"envmap\">\n        <string name=\"filename\" value=\"sky.pfm\"/>\n\
         \x20       <transform name=\"to_world\"><matrix value=\"{}\"/></transform>\n    </emitter>\n",
        sky::TO_WORLD
    )
}

/// The whole file: defaults (`spp`, `max_depth`), the body, then one radiancemeter per ray.
fn scene(body: &str, rays: &[(Vec3, Vec3)]) -> String {
    let mut s = String::from(
        "<scene version=\"3.0.0\">\n    <!-- mcbench export: sensor k is integral k (pixel row k / width, column k % width) -->\n\
         \x20   <default name=\"spp\" value=\"64\"/>\n    <default name=\"max_depth\" value=\"-1\"/>\n",
    );
    s.push_str(body);
    for (o, d) in rays {
        let _ = write!(
            s,
            "    <sensor type=\"radiancemeter\">\n        <point name=\"origin\" x=\"{}\" y=\"{}\" z=\"{}\"/>\n\
             \x20       <vector name=\"direction\" x=\"{}\" y=\"{}\" z=\"{}\"/>\n\
             \x20       <sampler type=\"independent\"><integer name=\"sample_count\" value=\"$spp\"/></sampler>\n\
             \x20       <film type=\"hdrfilm\"><integer name=\"width\" value=\"1\"/><integer name=\"height\" value=\"1\"/>\
             <string name=\"pixel_format\" value=\"rgb\"/><rfilter type=\"box\"/></film>\n    </sensor>\n",
            o.x, o.y, o.z, d.x, d.y, d.z
        );
    }
    s.push_str("</scene>\n");
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_sensor_per_pixel_in_row_major_order() {
        let files = gradient_plane("diffuse", &Params::new().with("resolution", 3.0)).unwrap();
        let xml = std::str::from_utf8(&files[0].bytes).unwrap();
        assert_eq!(xml.matches("<sensor type=\"radiancemeter\">").count(), 9);
        // The first sensor looks through the top-left pixel: up and to the left of the centre.
        let d = plane_camera().pixel_direction(0, 0, 3);
        assert!(
            d.x < 0.0
                && xml.contains(&format!("<vector name=\"direction\" x=\"{}\" y=\"{}\" z=\"{}\"/>", d.x, d.y, d.z))
        );
        assert!(xml.contains("value=\"0.8, 0.8, 0.8\""));
        let boxed = gradient_box("hg-0.1", &Params::new().with("resolution", 2.0)).unwrap();
        let xml = std::str::from_utf8(&boxed[0].bytes).unwrap();
        assert_eq!(xml.matches("radiancemeter").count(), 4);
        assert!(xml.contains("<phase type=\"hg\"><float name=\"g\" value=\"0.1\"/></phase>"));
        assert!(xml.contains("<float name=\"sigma_t\" value=\"2\"/>"));
    }
}
