//! The mutation strategies of differential evolution (eqs. 19–27, table in the [`super`] doc).
//! A leaf of its own because the matcher's errors name a strategy ([`super::super::MatchError`])
//! and the DE search returns those errors.

use std::fmt;

/// The nine mutation strategies of eqs. 19–27.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Strategy {
    Rand1,
    Rand2,
    Best1,
    Best2,
    CurrentToBest1,
    CurrentToBest2,
    RandToBest1,
    RandToBest2,
    EitherOr,
}

impl Strategy {
    /// All strategies, in the thesis's order.
    pub const ALL: [Strategy; 9] = [
        Strategy::Rand1,
        Strategy::Rand2,
        Strategy::Best1,
        Strategy::Best2,
        Strategy::CurrentToBest1,
        Strategy::CurrentToBest2,
        Strategy::RandToBest1,
        Strategy::RandToBest2,
        Strategy::EitherOr,
    ];

    /// The thesis's name ("rand/1", "current-to-best/2", "either-or", …).
    pub fn name(self) -> &'static str {
        match self {
            Strategy::Rand1 => "rand/1",
            Strategy::Rand2 => "rand/2",
            Strategy::Best1 => "best/1",
            Strategy::Best2 => "best/2",
            Strategy::CurrentToBest1 => "current-to-best/1",
            Strategy::CurrentToBest2 => "current-to-best/2",
            Strategy::RandToBest1 => "rand-to-best/1",
            Strategy::RandToBest2 => "rand-to-best/2",
            Strategy::EitherOr => "either-or",
        }
    }

    /// Parses [`Strategy::name`].
    pub fn from_name(name: &str) -> Option<Strategy> {
        Strategy::ALL.into_iter().find(|s| s.name() == name)
    }

    /// How many mutually distinct random members (other than the current one) it draws.
    pub fn random_members(self) -> usize {
        match self {
            Strategy::Best1 | Strategy::CurrentToBest1 => 2,
            Strategy::Rand1 | Strategy::RandToBest1 | Strategy::EitherOr => 3,
            Strategy::Best2 | Strategy::CurrentToBest2 => 4,
            Strategy::Rand2 | Strategy::RandToBest2 => 5,
        }
    }

    /// The smallest population it can run with: the current member plus its random members,
    /// and never fewer than 4.
    pub fn min_population(self) -> usize {
        (self.random_members() + 1).max(4)
    }
}

impl fmt::Display for Strategy {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}
