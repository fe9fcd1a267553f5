//! The colours of robots and their localizers, shared by the recording and the HTML report so a
//! robot looks the same in both: one colour per robot (matplotlib's tab10 order), its
//! localizers as shades of it.

/// Robot `index`'s colour (kept across its entities: body, truth, scan).
pub fn robot(index: u32) -> [u8; 3] {
    const PALETTE: [[u8; 3]; 8] = [
        [31, 119, 180],
        [255, 127, 14],
        [44, 160, 44],
        [214, 39, 40],
        [148, 103, 189],
        [140, 86, 75],
        [227, 119, 194],
        [23, 190, 207],
    ];
    PALETTE[index as usize % PALETTE.len()]
}

/// Localizer `k` of robot `robot`: a shade of the robot's colour (its truth has the colour
/// itself), darker for even `k` and lighter for odd, farther from it with each pair.
pub fn localizer(robot_index: u32, k: usize) -> [u8; 3] {
    let t = (0.3 + 0.2 * (k / 2) as f32).min(0.8);
    let shade = |c: u8| {
        let c = c as f32;
        let v = if k.is_multiple_of(2) {
            c * (1.0 - t)
        } else {
            c + (255.0 - c) * t
        };
        v.round() as u8
    };
    robot(robot_index).map(shade)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn localizers_are_distinct_shades_of_their_robot() {
        let base = robot(1);
        let shades: Vec<[u8; 3]> = (0..4).map(|k| localizer(1, k)).collect();
        for (k, s) in shades.iter().enumerate() {
            assert_ne!(*s, base, "shade {k}");
            // darker (even) or lighter (odd) in every channel
            for c in 0..3 {
                if k % 2 == 0 {
                    assert!(s[c] <= base[c]);
                } else {
                    assert!(s[c] >= base[c]);
                }
            }
        }
        let mut unique = shades.clone();
        unique.sort();
        unique.dedup();
        assert_eq!(unique.len(), 4);
        assert_eq!(robot(9), robot(1));
    }
}
