//! What machine a benchmark ran on, for its JSON rows: the shared 2-core CI machine's hardware
//! changes from day to day (a Xeon, a Zen 4 EPYC, a Zen 3 EPYC with half the L2 per core), and
//! figures from different processors do not compare. Read from /proc/cpuinfo on Linux; virtual
//! machines often report only a generic model name ("AMD EPYC"), so the family, model and cache
//! size go with it.

use serde::Serialize;
use std::sync::OnceLock;

/// The processor and the number of CPUs this process may use, e.g.
/// `AMD EPYC (family 25, model 1, cache 512 KB), 2 CPUs`.
pub fn describe() -> &'static str {
    static TEXT: OnceLock<String> = OnceLock::new();
    TEXT.get_or_init(|| {
        let cpus = std::thread::available_parallelism().map_or(1, |n| n.get());
        let info = std::fs::read_to_string("/proc/cpuinfo").unwrap_or_default();
        describe_cpuinfo(&info, cpus)
    })
}

/// [`describe`] from the text of /proc/cpuinfo (its first processor's fields).
pub fn describe_cpuinfo(cpuinfo: &str, cpus: usize) -> String {
    let field = |key: &str| {
        cpuinfo.lines().find_map(|l| {
            let (k, v) = l.split_once(':')?;
            (k.trim() == key).then(|| v.trim().to_string())
        })
    };
    let name = field("model name").unwrap_or_else(|| "unknown processor".into());
    let details: Vec<String> = [
        ("family", field("cpu family")),
        ("model", field("model")),
        ("cache", field("cache size")),
    ]
    .into_iter()
    .filter_map(|(label, v)| v.map(|v| format!("{label} {v}")))
    .collect();
    let plural = if cpus == 1 { "" } else { "s" };
    if details.is_empty() {
        format!("{name}, {cpus} CPU{plural}")
    } else {
        format!("{name} ({}), {cpus} CPU{plural}", details.join(", "))
    }
}

/// One `--json` bench row as a line: the row's fields in their order, then `machine`
/// ([`describe`]). A row that is not a JSON object is written as it is.
pub fn json_line(row: &impl Serialize) -> serde_json::Result<String> {
    let mut line = serde_json::to_string(row)?;
    if line.starts_with('{') && line.ends_with('}') {
        line.pop();
        if line.len() > 1 {
            line.push(',');
        }
        line.push_str("\"machine\":");
        line.push_str(&serde_json::to_string(describe())?);
        line.push('}');
    }
    Ok(line)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_virtual_amd_machine_is_named_with_family_model_and_cache() {
        let info = "processor\t: 0\nvendor_id\t: AuthenticAMD\ncpu family\t: 25\nmodel\t\t: 1\n\
                    model name\t: AMD EPYC\ncache size\t: 512 KB\n\nprocessor\t: 1\n\
                    cpu family\t: 25\nmodel\t\t: 1\nmodel name\t: AMD EPYC\n";
        assert_eq!(
            describe_cpuinfo(info, 2),
            "AMD EPYC (family 25, model 1, cache 512 KB), 2 CPUs"
        );
    }

    #[test]
    fn missing_fields_are_left_out_and_no_cpuinfo_is_unknown() {
        let arm = "processor\t: 0\nBogoMIPS\t: 50.00\nCPU part\t: 0xd0c\n";
        assert_eq!(describe_cpuinfo(arm, 1), "unknown processor, 1 CPU");
        let intel = "model name\t: Intel(R) Xeon(R) Platinum 8370C CPU @ 2.80GHz\nmodel\t: 106\n";
        assert_eq!(
            describe_cpuinfo(intel, 4),
            "Intel(R) Xeon(R) Platinum 8370C CPU @ 2.80GHz (model 106), 4 CPUs"
        );
    }

    #[test]
    fn json_lines_carry_the_machine() {
        #[derive(Serialize)]
        struct Row {
            robots: usize,
        }
        let line = json_line(&Row { robots: 3 }).unwrap();
        let v: serde_json::Value = serde_json::from_str(&line).unwrap();
        assert_eq!(v["robots"], 3);
        assert_eq!(v["machine"], describe());
        // the row's own fields keep their order, the machine comes last
        assert!(line.starts_with("{\"robots\":3,\"machine\":"), "{line}");
        #[derive(Serialize)]
        struct Empty {}
        let empty: serde_json::Value =
            serde_json::from_str(&json_line(&Empty {}).unwrap()).unwrap();
        assert_eq!(empty["machine"], describe());
    }
}
