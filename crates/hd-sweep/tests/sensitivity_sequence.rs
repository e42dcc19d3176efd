//! The Sobol' sequence against known points of the standard (Joe–Kuo, unscrambled)
//! sequence, and its stratification property.

use hd_sweep::sensitivity::SobolSequence;

/// First eight points in four dimensions, as printed by SciPy's
/// `qmc.Sobol(d=4, scramble=False).random(8)` (same direction numbers, same Gray-code order).
const FIRST_POINTS: [[f64; 4]; 8] = [
    [0.0, 0.0, 0.0, 0.0],
    [0.5, 0.5, 0.5, 0.5],
    [0.75, 0.25, 0.25, 0.25],
    [0.25, 0.75, 0.75, 0.75],
    [0.375, 0.375, 0.625, 0.875],
    [0.875, 0.875, 0.125, 0.375],
    [0.625, 0.125, 0.875, 0.625],
    [0.125, 0.625, 0.375, 0.125],
];

#[test]
fn first_points_match_the_standard_sequence() {
    let seq = SobolSequence::new(4).unwrap();
    for (n, want) in FIRST_POINTS.iter().enumerate() {
        assert_eq!(seq.point(n as u32), want, "point {n}");
    }
}

#[test]
fn high_dimensions_match_the_standard_sequence() {
    // Same source: point 5, dimensions 251–256; point 13, dimensions 101–103.
    let seq = SobolSequence::new(SobolSequence::MAX_DIMS).unwrap();
    assert_eq!(seq.point(5)[250..], [0.625, 0.625, 0.125, 0.125, 0.875, 0.875]);
    assert_eq!(seq.point(13)[100..103], [0.1875, 0.6875, 0.5625]);
}

/// The first 2^m points put exactly one point in each interval [k/2^m, (k+1)/2^m) of every
/// coordinate, with or without a digital shift.
#[test]
fn every_coordinate_is_stratified() {
    let m = 10;
    let n = 1usize << m;
    for seq in [
        SobolSequence::new(SobolSequence::MAX_DIMS).unwrap(),
        SobolSequence::new(SobolSequence::MAX_DIMS).unwrap().with_digital_shift(42),
    ] {
        let mut counts = vec![vec![0u32; n]; seq.dims()];
        let mut buf = vec![0.0; seq.dims()];
        for i in 0..n {
            seq.fill_point(i as u32, &mut buf);
            for (d, &x) in buf.iter().enumerate() {
                assert!((0.0..1.0).contains(&x));
                counts[d][(x * n as f64) as usize] += 1;
            }
        }
        for (d, c) in counts.iter().enumerate() {
            assert!(c.iter().all(|&k| k == 1), "dimension {} not stratified", d + 1);
        }
    }
}

/// Dimensions 1 and 2 form a (0, m, 2)-net: the first 2^m points fill each of the 2^m
/// equal boxes of every shape 2^-a × 2^-(m−a) exactly once.
#[test]
fn first_two_dimensions_form_a_net() {
    let m = 8;
    let n = 1usize << m;
    let seq = SobolSequence::new(2).unwrap();
    let pts: Vec<Vec<f64>> = (0..n as u32).map(|i| seq.point(i)).collect();
    for a in 0..=m {
        let (nx, ny) = (1usize << a, 1usize << (m - a));
        let mut counts = vec![0u32; n];
        for p in &pts {
            let (ix, iy) = ((p[0] * nx as f64) as usize, (p[1] * ny as f64) as usize);
            counts[ix * ny + iy] += 1;
        }
        assert!(counts.iter().all(|&k| k == 1), "boxes of shape 2^-{a} × 2^-{}", m - a);
    }
}
