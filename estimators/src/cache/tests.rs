//! Tests of the assembled cache: the cell sampler against its reported pdf, positivity of the pdf
//! (inheritance rule) and the refinement rules.

use super::*;
use mcbench_core::math::Vec3;
use mcbench_core::rng::stream;
use mcbench_core::samplers::testing::{assert_sampler_fits, SphereGrid};
use std::f64::consts::FRAC_1_SQRT_2;

/// A cache refined `depth` times whose PDF coefficients vary over four orders of magnitude.
fn shaped_cache<S: Scalar>(depth: u32) -> RadianceCache<S> {
    let config = CacheConfig { max_depth: depth, ..CacheConfig::surface(true) };
    let mut cache = RadianceCache::<S>::new(config);
    let mut rng = stream(3, "shaped cache");
    for _ in 0..20_000 {
        let s = cache.sample_uniform(&mut rng);
        let d = cache.domain().direction(s.st);
        // A lobe towards +x at 45 degrees elevation plus a small floor.
        let lobe = (d.dot(Vec3::new(FRAC_1_SQRT_2, 0.0, FRAC_1_SQRT_2)).max(0.0)).powi(8) * 100.0 + 0.01;
        cache.add_record(s.cell, Rgb([lobe, 0.5 * lobe, 0.1]), Rgb::ZERO);
    }
    assert_eq!(cache.grid().refinements(), depth);
    cache
}

/// Chi-square of the cache's cell sampler (tree, then uniform inside the cell) against the density
/// it reports, on bins that split every cache cell in four (so within-cell uniformity is tested),
/// in both storage precisions.
#[test]
fn chi_square_cache_cell_sampler() {
    fn check<S: Scalar>(seed: u64) {
        let cache = shaped_cache::<S>(3);
        assert_eq!(cache.grid().resolution(), (8, 8));
        let grid = SphereGrid::upper(16, 16);
        let domain = cache.domain();
        assert_sampler_fits(
            &format!("cache cell sampler ({})", S::NAME),
            &grid,
            300_000,
            seed,
            |rng| {
                let s = cache.sample(rng);
                assert_eq!(s.pdf, cache.pdf(s.st));
                domain.direction(s.st)
            },
            |d| domain.st_of(d).map_or(0.0, |st| cache.pdf(st)),
        );
    }
    check::<f64>(31);
    check::<f32>(32);
}

/// After refinement the density is positive in every cell and integrates to one; before it, the
/// sampler is uniform.
#[test]
fn pdf_is_positive_everywhere_and_normalised() {
    let fresh = RadianceCache::<f64>::new(CacheConfig::surface(true));
    assert_eq!(fresh.pdf(St { s: 0.2, t: 0.9 }), 1.0 / (2.0 * std::f64::consts::PI));
    let cache = shaped_cache::<f32>(4);
    let (ns, nt) = cache.grid().resolution();
    let omega = cache.domain().cell_solid_angle(ns, nt);
    let mut total = 0.0;
    for c in 0..cache.grid().cells() {
        let (i, j) = cache.grid().cell_ij(c);
        let p = cache.pdf(St { s: (i as f64 + 0.5) / ns as f64, t: (j as f64 + 0.5) / nt as f64 });
        assert!(p > 0.0, "cell {c} has zero density");
        total += p * omega;
    }
    assert!((total - 1.0).abs() < 1e-12, "{total}");
    assert!(cache.bytes() > cache.grid().cell_bytes());
}

/// The initial cell does not refine while its PDF coefficient is zero, whatever its count; it does
/// as soon as the coefficient is positive and the criterion holds. Refinement stops at max_depth.
#[test]
fn refinement_rules() {
    let config = CacheConfig { max_depth: 2, ..CacheConfig::surface(true) };
    let mut cache = RadianceCache::<f64>::new(config);
    let st = St { s: 0.1, t: 0.1 };
    for _ in 0..100 {
        let g = cache.g(ControlVariate::Constant, st);
        assert!(!cache.add_record(0, Rgb::ZERO, g));
    }
    assert_eq!(cache.grid().refinements(), 0);
    assert!(cache.add_record(0, Rgb::splat(1.0), Rgb::ZERO), "criterion long met, coefficient now positive");
    assert_eq!(cache.grid().cells(), 4);
    assert!((cache.grid().mean_count() - 25.0).abs() < 1e-12, "101 / 4 = 25 records per child");
    // Already above the criterion: the next record refines again, then max_depth stops it.
    assert!(cache.add_record(1, Rgb::splat(1.0), Rgb::ZERO));
    for _ in 0..1000 {
        let s = cache.sample(&mut stream(4, "rules"));
        cache.add_record(s.cell, Rgb::splat(2.0), Rgb::ZERO);
    }
    assert_eq!(cache.grid().refinements(), 2);
    assert!(cache.grid().pdf_coefficients().all(|p| p > 0.0));
}

/// 2e6 records into one small cache: counters, means and the tree stay finite and consistent, and
/// a firefly a billion times larger than the rest only rescales the tree.
#[test]
fn long_runs_and_fireflies() {
    let config = CacheConfig { max_depth: 3, ..CacheConfig::surface(true) };
    let mut cache = RadianceCache::<f32>::new(config);
    let mut rng = stream(5, "long run");
    for k in 0..2_000_000u32 {
        let s = cache.sample(&mut rng);
        let v = if k == 1_000_000 { 1e9 } else { 1.0 + s.st.t };
        let g = cache.g(ControlVariate::Bilinear, s.st);
        cache.add_record(s.cell, Rgb::splat(v), g);
    }
    assert_eq!(cache.grid().records(), (0..64).map(|c| u64::from(cache.grid().count(c))).sum::<u64>());
    assert!(cache.grid().records() > 1_900_000);
    let big_g = cache.integral(ControlVariate::Bilinear);
    assert!(big_g.is_finite() && big_g[0] > 0.0);
    assert!(cache.grid().pdf_coefficients().all(|p| p > 0.0 && p.is_finite()));
}

/// The storage spans a cache reports (for huge pages) are exactly its heap bytes: cells, PDF
/// coefficients and, with `is1`, the block sums.
#[test]
fn storage_spans_are_the_heap_bytes() {
    let with = shaped_cache::<f64>(3);
    let spans: Vec<_> = with.storage_spans().collect();
    assert_eq!(spans.len(), 3);
    assert_eq!(spans.iter().map(|s| s.1).sum::<usize>(), with.bytes());
    assert!(spans.iter().all(|&(start, len)| start % std::mem::align_of::<f32>() == 0 && len > 0));
    let without = RadianceCache::<f32>::new(CacheConfig::surface(false));
    assert_eq!(without.storage_spans().map(|s| s.1).sum::<usize>(), without.bytes());
    assert_eq!(without.storage_spans().count(), 2);
}

/// The prefetching draw is the same draw: the same cells, directions and densities for the same
/// random numbers, in both precisions (prefetches change timing only).
#[test]
fn prefetching_draws_are_the_same_draws() {
    fn check<S: Scalar>() {
        let cache = shaped_cache::<S>(4);
        let (mut a, mut b) = (stream(9, "prefetch"), stream(9, "prefetch"));
        for _ in 0..50_000 {
            assert_eq!(cache.sample(&mut a), cache.sample_prefetching(&mut b));
        }
        let tree = CellSampler::new(cache.grid().pdf_slice());
        for _ in 0..10_000 {
            let plain = tree.sample_weighted(cache.grid().pdf_slice(), &mut a);
            let mut block = None;
            let with = tree.sample_weighted_prefetching(cache.grid().pdf_slice(), &mut b, |r| block = Some(r));
            assert_eq!(plain, with);
            // The range handed out for prefetching is the drawn cell's block.
            let (cell, q) = with.expect("a positive total");
            assert!(q > 0 && block.is_some_and(|r| r.contains(&cell) && r.len() <= 32));
        }
    }
    check::<f64>();
    check::<f32>();
}
