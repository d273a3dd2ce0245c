//! Paths for the viewer page from a JSON file: the output of `fuzzyvox plan --json` (one flight
//! from its `waypoints`), a `{"paths": [...]}` object of [`PagePath`]s (what the demo writes
//! beside each map), or an array of either.

use std::path::Path;

use fuzzyvox_core::error::{Error, Result};
use serde_json::Value;

use super::page::{PagePath, PathKind};

/// Largest paths file read (64 MiB).
pub const MAX_PATHS_BYTES: u64 = 64 << 20;

/// Reads the paths in `path` (see the module's documentation for the forms accepted).
pub fn read_paths(path: &Path) -> Result<Vec<PagePath>> {
    use std::io::Read;
    let io = |source| Error::Io {
        path: path.to_path_buf(),
        source,
    };
    let mut bytes = Vec::new();
    std::fs::File::open(path)
        .map_err(io)?
        .take(MAX_PATHS_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(io)?;
    if bytes.len() as u64 > MAX_PATHS_BYTES {
        return Err(Error::Format {
            path: path.to_path_buf(),
            reason: fuzzyvox_core::error::FormatError::Invalid(format!(
                "longer than {MAX_PATHS_BYTES} bytes: not a paths file"
            )),
        });
    }
    parse_paths(&bytes).map_err(|reason| Error::Format {
        path: path.to_path_buf(),
        reason: fuzzyvox_core::error::FormatError::Invalid(reason),
    })
}

/// Parses paths from JSON bytes; the error says what is wrong.
pub fn parse_paths(bytes: &[u8]) -> std::result::Result<Vec<PagePath>, String> {
    let value: Value = serde_json::from_slice(bytes).map_err(|e| format!("not JSON paths: {e}"))?;
    let mut out = Vec::new();
    collect(&value, &mut out)?;
    Ok(out)
}

fn collect(value: &Value, out: &mut Vec<PagePath>) -> std::result::Result<(), String> {
    match value {
        Value::Array(items) => items.iter().try_for_each(|v| collect(v, out)),
        Value::Object(object) => {
            if let Some(paths) = object.get("paths") {
                let Value::Array(items) = paths else {
                    return Err("\"paths\" must be an array".into());
                };
                for item in items {
                    out.push(path_of(item, out.len())?);
                }
                Ok(())
            } else if let Some(waypoints) = object.get("waypoints") {
                out.push(PagePath {
                    name: format!("plan {}", out.len() + 1),
                    kind: PathKind::Flight,
                    ok: true,
                    points: points(waypoints)?,
                });
                Ok(())
            } else if object.contains_key("points") {
                out.push(path_of(value, out.len())?);
                Ok(())
            } else {
                Err(
                    "expected `fuzzyvox plan --json` output (\"waypoints\"), an object with \
                     \"paths\", or a path with \"points\""
                        .into(),
                )
            }
        }
        _ => Err("expected a JSON object or array of paths".into()),
    }
}

fn path_of(value: &Value, index: usize) -> std::result::Result<PagePath, String> {
    let kind = match value.get("kind").and_then(Value::as_str) {
        None | Some("flight") => PathKind::Flight,
        Some("trajectory") => PathKind::Trajectory,
        Some(other) => {
            return Err(format!(
                "unknown path kind {other:?} (flight or trajectory)"
            ));
        }
    };
    Ok(PagePath {
        name: value
            .get("name")
            .and_then(Value::as_str)
            .map_or_else(|| format!("path {}", index + 1), str::to_string),
        kind,
        ok: value.get("ok").and_then(Value::as_bool).unwrap_or(true),
        points: points(value.get("points").unwrap_or(&Value::Null))?,
    })
}

fn points(value: &Value) -> std::result::Result<Vec<[f64; 3]>, String> {
    let Value::Array(items) = value else {
        return Err("points must be an array of [x, y, z]".into());
    };
    items
        .iter()
        .map(|p| {
            let xyz: Option<Vec<f64>> = p
                .as_array()
                .map(|a| a.iter().filter_map(Value::as_f64).collect());
            match xyz {
                Some(v) if v.len() == 3 && v.iter().all(|c| c.is_finite()) => {
                    Ok([v[0], v[1], v[2]])
                }
                _ => Err(format!(
                    "a point must be three finite numbers [x, y, z], got {p}"
                )),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plan_output_path_lists_and_arrays_are_read() {
        let plan = br#"{"map": "m.fvx", "waypoints": [[0, 0, 1], [1, 2, 1]], "length_m": 2.2}"#;
        let paths = parse_paths(plan).unwrap();
        assert_eq!(paths.len(), 1);
        assert_eq!(paths[0].points[1], [1.0, 2.0, 1.0]);
        let list = br#"{"paths": [{"name": "camera", "kind": "trajectory", "points": [[0,0,0]]},
                                  {"name": "f1", "ok": false, "points": [[0,0,0],[1,1,1]]}]}"#;
        let paths = parse_paths(list).unwrap();
        assert_eq!(paths[0].kind, PathKind::Trajectory);
        assert!(!paths[1].ok);
        let both = format!(
            "[{}, {}]",
            std::str::from_utf8(plan).unwrap(),
            std::str::from_utf8(list).unwrap()
        );
        assert_eq!(parse_paths(both.as_bytes()).unwrap().len(), 3);
    }

    #[test]
    fn bad_paths_say_what_is_wrong() {
        for (bad, says) in [
            (&b"not json"[..], "not JSON"),
            (br#"{"waypoints": [[0, 0]]}"#, "three finite numbers"),
            (
                br#"{"paths": [{"kind": "orbit", "points": []}]}"#,
                "unknown path kind",
            ),
            (br#"{"paths": 3}"#, "must be an array"),
            (br#"{"other": 1}"#, "expected"),
            (br#"7"#, "expected a JSON object"),
        ] {
            let error = parse_paths(bad).unwrap_err();
            assert!(error.contains(says), "{error}");
        }
    }
}
