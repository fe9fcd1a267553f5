//! Parameter sets: the `--set` overrides shared by every run, and one combination of `--sweep`
//! values (Cartesian product, the first sweep varying slowest) and `--zip` values (advancing
//! together, the last axis) per set. Each set's scenario is the file with its overrides applied,
//! loaded and validated as a scenario file is.

use super::args::{split_key_value, split_values};
use super::runner::MAX_RUNS;
use crate::scenario::overrides::Override;

/// One override of a batch (or replay) flag; the seed is not among them: it comes from
/// `--seeds` (`--seed` in a replay).
fn batch_override(flag: &'static str, key: &str, text: &str) -> anyhow::Result<Override> {
    let o = Override::new(flag, key, text)?;
    if o.is_seed() {
        anyhow::bail!("{flag} {key}={text}: the seed of each run comes from --seeds");
    }
    Ok(o)
}

/// The overrides of every parameter set, in set order, and the keys that vary or are set.
#[derive(Clone, Debug)]
pub struct SetPlan {
    /// Every `--set`, `--sweep` and `--zip` key in command-line order of the flags' kinds.
    pub keys: Vec<String>,
    /// Per set: its overrides (the `--set` ones first).
    pub sets: Vec<Vec<Override>>,
}

fn overrides_of(flag: &'static str, arg: &str) -> anyhow::Result<Vec<Override>> {
    let (k, v) = split_key_value(flag, arg)?;
    split_values(flag, arg, v)?
        .iter()
        .map(|v| batch_override(flag, k, v))
        .collect()
}

/// Builds the parameter sets of `--set`, `--sweep` and `--zip` arguments.
pub fn plan_sets(sets: &[String], sweeps: &[String], zips: &[String]) -> anyhow::Result<SetPlan> {
    let mut fixed = Vec::new();
    for s in sets {
        let (k, v) = split_key_value("--set", s)?;
        fixed.push(batch_override("--set", k, v)?);
    }
    // axes: each a list of points, each point a list of overrides
    let mut axes: Vec<Vec<Vec<Override>>> = Vec::new();
    for s in sweeps {
        axes.push(
            overrides_of("--sweep", s)?
                .into_iter()
                .map(|o| vec![o])
                .collect(),
        );
    }
    if !zips.is_empty() {
        let lists = zips
            .iter()
            .map(|z| overrides_of("--zip", z))
            .collect::<anyhow::Result<Vec<_>>>()?;
        let n = lists[0].len();
        if let Some((z, l)) = zips.iter().zip(&lists).find(|(_, l)| l.len() != n) {
            anyhow::bail!(
                "--zip {z}: {} values, but --zip {} has {n}: every --zip needs the same number",
                l.len(),
                zips[0]
            );
        }
        axes.push(
            (0..n)
                .map(|i| lists.iter().map(|l| l[i].clone()).collect())
                .collect(),
        );
    }
    let mut keys: Vec<String> = fixed.iter().map(|o| o.key.clone()).collect();
    let mut flags: Vec<&str> = fixed.iter().map(|o| o.flag).collect();
    for axis in &axes {
        for o in &axis[0] {
            keys.push(o.key.clone());
            flags.push(o.flag);
        }
    }
    for (i, k) in keys.iter().enumerate() {
        if let Some(j) = keys[..i].iter().position(|p| p == k) {
            anyhow::bail!(
                "{k}: given twice ({} and {}); each key may be set or varied once",
                flags[j],
                flags[i]
            );
        }
    }
    let lengths: Vec<usize> = axes.iter().map(Vec::len).collect();
    let count = lengths.iter().try_fold(1usize, |n, &l| n.checked_mul(l));
    if count.is_none_or(|n| n > MAX_RUNS) {
        let product: Vec<String> = lengths.iter().map(usize::to_string).collect();
        anyhow::bail!(
            "--sweep/--zip: {} parameter sets ({}), more than the {MAX_RUNS} runs a batch may have",
            count.map_or("too many".to_string(), |n| n.to_string()),
            product.join(" × ")
        );
    }
    // odometer over the axes, the first axis varying slowest
    let mut out = Vec::new();
    let mut at = vec![0usize; axes.len()];
    loop {
        let mut set = fixed.clone();
        for (axis, &i) in axes.iter().zip(&at) {
            set.extend(axis[i].iter().cloned());
        }
        out.push(set);
        let mut d = axes.len();
        loop {
            if d == 0 {
                return Ok(SetPlan { keys, sets: out });
            }
            d -= 1;
            at[d] += 1;
            if at[d] < axes[d].len() {
                break;
            }
            at[d] = 0;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn strs(v: &[&str]) -> Vec<String> {
        v.iter().map(|s| s.to_string()).collect()
    }

    fn show(p: &SetPlan) -> Vec<String> {
        p.sets
            .iter()
            .map(|s| {
                s.iter()
                    .map(|o| format!("{}={}", o.key, o.text))
                    .collect::<Vec<_>>()
                    .join(" ")
            })
            .collect()
    }

    #[test]
    fn product_and_zip() {
        let p = plan_sets(
            &strs(&["duration=5"]),
            &strs(&["a=1,2", "b=x,y"]),
            &strs(&["c=10,20", "d=[1,2],[3,4]"]),
        )
        .unwrap();
        assert_eq!(p.keys, ["duration", "a", "b", "c", "d"]);
        let s = show(&p);
        assert_eq!(s.len(), 8);
        assert_eq!(s[0], "duration=5 a=1 b=x c=10 d=[1,2]");
        assert_eq!(s[1], "duration=5 a=1 b=x c=20 d=[3,4]");
        assert_eq!(s[2], "duration=5 a=1 b=y c=10 d=[1,2]");
        assert_eq!(s[7], "duration=5 a=2 b=y c=20 d=[3,4]");
        assert_eq!(show(&plan_sets(&[], &[], &[]).unwrap()), [""]);
    }

    #[test]
    fn plan_errors() {
        let e = |s: &[&str], w: &[&str], z: &[&str]| {
            plan_sets(&strs(s), &strs(w), &strs(z))
                .unwrap_err()
                .to_string()
        };
        assert!(e(&["a=1"], &["a=1,2"], &[]).contains("a: given twice (--set and --sweep)"));
        assert!(e(&[], &[], &["a=1,2", "b=1"]).contains("every --zip needs the same number"));
        assert!(e(&["duration"], &[], &[]).contains("--set duration: expected KEY=VALUE"));
        assert!(e(&[], &["seed=1,2"], &[]).contains("the seed of each run comes from --seeds"));
        // the product is refused before it is built
        let values = (0..1000)
            .map(|i| i.to_string())
            .collect::<Vec<_>>()
            .join(",");
        let sweeps: Vec<String> = ["a", "b"].iter().map(|k| format!("{k}={values}")).collect();
        let zips: Vec<String> = ["c", "d"].iter().map(|k| format!("{k}={values}")).collect();
        let sweeps: Vec<&str> = sweeps.iter().map(String::as_str).collect();
        let zips: Vec<&str> = zips.iter().map(String::as_str).collect();
        assert!(e(&[], &sweeps, &zips).contains(
            "--sweep/--zip: 1000000000 parameter sets (1000 × 1000 × 1000), more than the \
                 1000000 runs a batch may have"
        ));
    }
}
