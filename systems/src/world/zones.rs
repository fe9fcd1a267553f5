//! Outdoor zones that degrade GPS and compass readings ([Park thesis §5.3.1]): in the open the
//! thesis's receiver sat within about 1.25 m on average, under partial tree cover up to 5.85 m and
//! between buildings up to 6.31 m off (the *mean* fix, so the error has a slow bias, not only
//! noise), and its compass was off by under 1° except near electromagnetic interference, where it
//! was off by 8–20°.
//!
//! A zone is a polygon or a circle in local metres with a kind that sets default parameters
//! ([`ZoneKind::gps`], [`ZoneKind::compass`]); a scenario may override them per zone. Where zones
//! overlap the one listed last wins; outside every zone the open-sky parameters hold.

use bevy_ecs::prelude::Resource;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ZoneKind {
    Open,
    Trees,
    Buildings,
    /// Electromagnetic interference (power lines, transformers, steel).
    EmInterference,
}

impl ZoneKind {
    pub fn parse(s: &str) -> Option<ZoneKind> {
        Some(match s {
            "open" => ZoneKind::Open,
            "trees" => ZoneKind::Trees,
            "buildings" => ZoneKind::Buildings,
            "em" | "em_interference" => ZoneKind::EmInterference,
            _ => return None,
        })
    }

    pub fn as_str(self) -> &'static str {
        match self {
            ZoneKind::Open => "open",
            ZoneKind::Trees => "trees",
            ZoneKind::Buildings => "buildings",
            ZoneKind::EmInterference => "em_interference",
        }
    }

    /// Default GPS error model of the kind.
    pub fn gps(self) -> GpsZone {
        let open = GpsZone {
            mu: 1.0,
            sigma: 0.506,
            bias_std: 1.0,
            bias_tau: 120.0,
            outlier_probability: 0.002,
            outlier_range: [20.0, 60.0],
        };
        match self {
            ZoneKind::Open | ZoneKind::EmInterference => open,
            ZoneKind::Trees => GpsZone {
                mu: 1.3,
                sigma: 0.6,
                bias_std: 3.5,
                outlier_probability: 0.01,
                ..open
            },
            ZoneKind::Buildings => GpsZone {
                mu: 1.5,
                sigma: 0.6,
                bias_std: 4.5,
                outlier_probability: 0.02,
                ..open
            },
        }
    }

    /// Default compass error model of the kind.
    pub fn compass(self) -> CompassZone {
        match self {
            ZoneKind::EmInterference => CompassZone {
                deflection_deg: [8.0, 20.0],
            },
            _ => CompassZone {
                deflection_deg: [0.0, 0.0],
            },
        }
    }
}

/// GPS error parameters in a zone. The distance between a fix and the truth is the slow bias
/// plus a fresh error per fix whose length is log-normal, LN(μ, σ) metres (the thesis's sensor
/// model: LN(1, 0.506), most errors 0.5–4 m), in a uniformly random direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GpsZone {
    pub mu: f64,
    pub sigma: f64,
    /// Stationary standard deviation (m, per axis) of the bias, a first-order Gauss–Markov
    /// process with time constant `bias_tau` (s): the mean fix drifts metres off the truth.
    pub bias_std: f64,
    pub bias_tau: f64,
    /// Probability that a fix is an outlier, off by a distance uniform in `outlier_range` (m).
    pub outlier_probability: f64,
    pub outlier_range: [f64; 2],
}

/// Compass error in a zone: a deflection (degrees) from `deflection_deg[1]` at the zone's centre
/// falling linearly to `deflection_deg[0]` at its edge, with the zone's sign.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CompassZone {
    pub deflection_deg: [f64; 2],
}

#[derive(Clone, Debug, PartialEq)]
pub enum ZoneShape {
    /// Vertices in order (either orientation), local metres.
    Polygon(Vec<[f64; 2]>),
    Circle {
        centre: [f64; 2],
        radius: f64,
    },
}

impl ZoneShape {
    pub fn contains(&self, p: [f64; 2]) -> bool {
        match self {
            ZoneShape::Circle { centre, radius } => {
                (p[0] - centre[0]).hypot(p[1] - centre[1]) <= *radius
            }
            ZoneShape::Polygon(v) => {
                // even-odd rule
                let mut inside = false;
                let mut j = v.len().wrapping_sub(1);
                for i in 0..v.len() {
                    let (a, b) = (v[i], v[j]);
                    if (a[1] > p[1]) != (b[1] > p[1])
                        && p[0] < (b[0] - a[0]) * (p[1] - a[1]) / (b[1] - a[1]) + a[0]
                    {
                        inside = !inside;
                    }
                    j = i;
                }
                inside
            }
        }
    }

    /// Centre and reach (largest distance from the centre to the boundary): the circle's, or
    /// the polygon's vertex mean and its farthest vertex.
    pub fn centre_and_reach(&self) -> ([f64; 2], f64) {
        match self {
            ZoneShape::Circle { centre, radius } => (*centre, *radius),
            ZoneShape::Polygon(v) => {
                let n = v.len().max(1) as f64;
                let c = v
                    .iter()
                    .fold([0.0, 0.0], |s, p| [s[0] + p[0] / n, s[1] + p[1] / n]);
                let r = v
                    .iter()
                    .map(|p| (p[0] - c[0]).hypot(p[1] - c[1]))
                    .fold(0.0, f64::max);
                (c, r)
            }
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Zone {
    pub name: String,
    pub kind: ZoneKind,
    pub shape: ZoneShape,
    pub gps: GpsZone,
    pub compass: CompassZone,
    /// +1 or −1: the direction the interference turns the compass.
    pub compass_sign: f64,
}

impl Zone {
    /// A zone with its kind's default parameters, deflecting the compass clockwise.
    pub fn new(name: impl Into<String>, kind: ZoneKind, shape: ZoneShape) -> Self {
        Zone {
            name: name.into(),
            kind,
            shape,
            gps: kind.gps(),
            compass: kind.compass(),
            compass_sign: 1.0,
        }
    }

    /// Compass deflection (radians, clockwise positive) at `p`, which lies in the zone.
    pub fn deflection(&self, p: [f64; 2]) -> f64 {
        let [edge, centre] = self.compass.deflection_deg;
        let (c, reach) = self.shape.centre_and_reach();
        let t = if reach > 0.0 {
            ((p[0] - c[0]).hypot(p[1] - c[1]) / reach).clamp(0.0, 1.0)
        } else {
            0.0
        };
        self.compass_sign * (centre + (edge - centre) * t).to_radians()
    }
}

/// Every zone of the world, in scenario order.
#[derive(Resource, Clone, Debug, Default, PartialEq)]
pub struct Zones {
    pub zones: Vec<Zone>,
}

impl Zones {
    /// The zone at `p` (the last listed that contains it), `None` in the open.
    pub fn at(&self, p: [f64; 2]) -> Option<&Zone> {
        self.zones.iter().rev().find(|z| z.shape.contains(p))
    }

    /// GPS parameters at `p`.
    pub fn gps_at(&self, p: [f64; 2]) -> GpsZone {
        self.at(p).map_or(ZoneKind::Open.gps(), |z| z.gps)
    }

    /// Compass deflection (radians, clockwise positive) at `p`.
    pub fn compass_deflection_at(&self, p: [f64; 2]) -> f64 {
        self.at(p).map_or(0.0, |z| z.deflection(p))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shapes_contain_what_they_should() {
        let square = ZoneShape::Polygon(vec![[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]]);
        assert!(square.contains([5.0, 5.0]));
        assert!(!square.contains([11.0, 5.0]));
        assert!(!square.contains([5.0, -0.1]));
        // an L shape: the notch is outside
        let l = ZoneShape::Polygon(vec![
            [0.0, 0.0],
            [10.0, 0.0],
            [10.0, 4.0],
            [4.0, 4.0],
            [4.0, 10.0],
            [0.0, 10.0],
        ]);
        assert!(l.contains([2.0, 8.0]) && l.contains([8.0, 2.0]));
        assert!(!l.contains([8.0, 8.0]));
        let c = ZoneShape::Circle {
            centre: [1.0, 1.0],
            radius: 2.0,
        };
        assert!(c.contains([2.0, 2.0]) && !c.contains([3.0, 3.0]));
    }

    #[test]
    fn the_last_zone_wins_and_the_open_is_the_default() {
        let zones = Zones {
            zones: vec![
                Zone::new(
                    "wood",
                    ZoneKind::Trees,
                    ZoneShape::Polygon(vec![[0.0, 0.0], [20.0, 0.0], [20.0, 20.0], [0.0, 20.0]]),
                ),
                Zone::new(
                    "substation",
                    ZoneKind::EmInterference,
                    ZoneShape::Circle {
                        centre: [20.0, 20.0],
                        radius: 10.0,
                    },
                ),
            ],
        };
        assert_eq!(
            zones.gps_at([5.0, 5.0]).bias_std,
            ZoneKind::Trees.gps().bias_std
        );
        assert_eq!(zones.at([18.0, 18.0]).unwrap().name, "substation");
        assert_eq!(zones.gps_at([50.0, 50.0]), ZoneKind::Open.gps());
        assert_eq!(zones.compass_deflection_at([5.0, 5.0]), 0.0);
        // 20° at the centre of the interference, 8° at its edge
        let d = |p| zones.compass_deflection_at(p).to_degrees();
        assert!((d([20.0, 20.0]) - 20.0).abs() < 1e-9);
        assert!((d([29.99, 20.0]) - 8.0).abs() < 0.02);
        assert!((d([25.0, 20.0]) - 14.0).abs() < 1e-9);
    }

    #[test]
    fn kinds_parse() {
        for k in [
            ZoneKind::Open,
            ZoneKind::Trees,
            ZoneKind::Buildings,
            ZoneKind::EmInterference,
        ] {
            assert_eq!(ZoneKind::parse(k.as_str()), Some(k));
        }
        assert_eq!(ZoneKind::parse("em"), Some(ZoneKind::EmInterference));
        assert_eq!(ZoneKind::parse("forest"), None);
    }
}
