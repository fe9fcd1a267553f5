//! Deterministic spatial subsampling of a scan for the improved matcher's searches: walk the
//! points in order and keep one whenever it is at least `spacing` from the last kept point, then
//! thin evenly to at most `max` points. Near the sensor a scan is far denser than far away (the
//! beams fan out), so this evens out the weight of near and far surfaces and cuts the cost of
//! every evaluation; cf. the voxel filters of Censi's PLICP and of Cartographer. The thesis
//! itself ([Hospital thesis §6]) rasterises every point.

/// Points at least `spacing` apart along the scan, at most `max` of them (every k-th after
/// spacing if there are more). Order is kept.
pub(crate) fn subsample(points: &[[f32; 2]], spacing: f32, max: usize) -> Vec<[f32; 2]> {
    let s2 = spacing * spacing;
    let mut kept: Vec<[f32; 2]> = Vec::with_capacity(points.len().min(4 * max.max(1)));
    for p in points {
        match kept.last() {
            Some(l) if (p[0] - l[0]).powi(2) + (p[1] - l[1]).powi(2) < s2 => {}
            _ => kept.push(*p),
        }
    }
    if max == 0 {
        return Vec::new();
    }
    if kept.len() > max {
        let n = kept.len();
        // evenly spread picks: index ⌊j · n / max⌋
        kept = (0..max).map(|j| kept[j * n / max]).collect();
    }
    kept
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keeps_spacing_and_cap() {
        let line: Vec<[f32; 2]> = (0..1000).map(|k| [k as f32 * 0.01, 0.0]).collect();
        // every 10th point is 0.1 m (± rounding) from the last kept one
        let s = subsample(&line, 0.095, 1000);
        assert_eq!(s.len(), 100);
        assert!(s.windows(2).all(|w| w[1][0] - w[0][0] >= 0.095));
        let capped = subsample(&line, 0.095, 30);
        assert_eq!(capped.len(), 30);
        assert!(capped.windows(2).all(|w| w[1][0] > w[0][0]));
        assert!(subsample(&line, 0.1, 0).is_empty());
        assert!(subsample(&[], 0.1, 10).is_empty());
    }
}
