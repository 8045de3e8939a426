//! The thesis's proposed improvements of the hybrid drive (sections 8.2 and
//! 9.2) as rig files of kind `hybrid-variant`: a base hybrid rig plus
//! changes assembled from existing components.
//!
//! ```json
//! { "kind": "hybrid-variant", "name": "hybrid-solenoid", "description": "...",
//!   "base": "wang-hybrid",
//!   "solenoid_valves": { "area_m2": 1.5e-5,
//!                        "orifice": { "cd": 0.65, "density": 900.0, "dp_transition": 1000.0 } },
//!   "needle_area_by_speed": [ { "speed_mm_s": 50.0, "area_m2": 4.2e-6 } ] }
//! ```
//!
//! * `base`: a preset name or the path of a `hybrid-pump` rig file (relative
//!   to the variant file);
//! * `solenoid_valves` (variant (a)): relief valves 1 and 2 replaced by on/off
//!   valves ([`SwitchedOrifice`]) open while
//!   the pump command feeds their line (valve 1 for a positive command);
//! * `needle_area_by_speed` (variant (b)): the needle valve's opening area
//!   \[m²\] per speed; a scenario takes the entry of the nearest speed.

use crate::components::SwitchedOrifice;
use crate::hybrid::{nodes, WangHybrid};
use crate::rig::RigError;
use crate::signal::Signal;
use crate::{Circuit, Component};
use hydrocyl_ports::Area;
use hydrocyl_valves::orifice::Orifice;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The JSON `kind` of a variant file.
pub const KIND: &str = "hybrid-variant";

/// Makes a variant file's relative `base` path (one that is not a preset
/// name) relative to `dir`, the variant file's folder, so that the value
/// runs from any working directory. Other rig values are left as they are.
pub fn resolve_base(v: &mut serde_json::Value, dir: Option<&Path>) {
    if v.get("kind").and_then(serde_json::Value::as_str) != Some(KIND) {
        return;
    }
    let (Some(dir), Some(base)) = (dir, v.get("base").and_then(serde_json::Value::as_str)) else {
        return;
    };
    if crate::rig::preset(base).is_none() && Path::new(base).is_relative() {
        let joined = dir.join(base).display().to_string();
        v["base"] = serde_json::Value::from(joined);
    }
}

/// Solenoid valves replacing relief valves 1 and 2.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SolenoidSpec {
    /// Open area of each valve \[m²\].
    pub area_m2: f64,
    /// Orifice law of the open valve.
    pub orifice: Orifice,
}

/// One needle opening for one speed.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NeedleSetting {
    /// Speed amplitude \[mm/s\].
    pub speed_mm_s: f64,
    /// Needle opening area Avn \[m²\].
    pub area_m2: f64,
}

/// A variant rig file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HybridVariant {
    /// Always `hybrid-variant`.
    pub kind: String,
    /// The variant's name (the `system` column of the matrix).
    pub name: String,
    /// Free text: what is changed and why.
    pub description: String,
    /// The base hybrid rig: a preset name or a rig-file path.
    pub base: String,
    /// Variant (a): solenoid valves instead of relief valves 1 and 2.
    #[serde(default)]
    pub solenoid_valves: Option<SolenoidSpec>,
    /// Variant (b): needle opening per speed.
    #[serde(default)]
    pub needle_area_by_speed: Option<Vec<NeedleSetting>>,
}

impl HybridVariant {
    /// Checks the parameters; errors name the field.
    pub fn validate(&self) -> Result<(), RigError> {
        let bad = |why: String| {
            Err(RigError::Invalid {
                path: self.name.clone(),
                why,
            })
        };
        if self.kind != KIND {
            return bad(format!("`kind` must be `{KIND}`, got `{}`", self.kind));
        }
        if let Some(s) = &self.solenoid_valves {
            if !(s.area_m2.is_finite() && s.area_m2 > 0.0) {
                return bad(format!(
                    "`solenoid_valves.area_m2` = {} must be positive",
                    s.area_m2
                ));
            }
            if let Err(e) = s.orifice.validate("solenoid valve") {
                return bad(format!(
                    "`solenoid_valves.orifice.{}` = {}: {}",
                    e.name, e.value, e.reason
                ));
            }
        }
        if let Some(t) = &self.needle_area_by_speed {
            if t.is_empty() {
                return bad("`needle_area_by_speed` is empty (leave it out instead)".into());
            }
            for (i, s) in t.iter().enumerate() {
                if !(s.speed_mm_s.is_finite() && s.speed_mm_s > 0.0) {
                    return bad(format!(
                        "`needle_area_by_speed[{i}].speed_mm_s` = {} must be positive",
                        s.speed_mm_s
                    ));
                }
                if !(s.area_m2.is_finite() && s.area_m2 > 0.0) {
                    return bad(format!(
                        "`needle_area_by_speed[{i}].area_m2` = {} must be positive",
                        s.area_m2
                    ));
                }
            }
        }
        Ok(())
    }

    /// The needle area for `speed_mm_s` \[m²\]: the entry of the nearest speed.
    pub fn needle_area_for(&self, speed_mm_s: f64) -> Option<f64> {
        self.needle_area_by_speed.as_ref().and_then(|t| {
            t.iter()
                .min_by(|a, b| {
                    (a.speed_mm_s - speed_mm_s)
                        .abs()
                        .total_cmp(&(b.speed_mm_s - speed_mm_s).abs())
                })
                .map(|s| s.area_m2)
        })
    }

    /// Changes the variant makes to the base rig's parameters: the needle
    /// opening for `speed_mm_s` (the entry of the nearest speed) when the
    /// variant sets one per speed and a speed is given.
    pub fn apply_to_rig(&self, rig: &mut WangHybrid, speed_mm_s: Option<f64>) {
        if let Some(a) = speed_mm_s.and_then(|v| self.needle_area_for(v)) {
            rig.needle.area = Area::new(a);
        }
    }

    /// Changes the variant makes to the assembled components: relief valves
    /// 1 and 2 replaced by solenoid valves switched by the pump command's sign
    /// (variant (a)); nothing otherwise.
    pub fn swap_components(&self, comps: &mut [Box<dyn Component>]) {
        let Some(spec) = self.solenoid_valves else {
            return;
        };
        for c in comps.iter_mut() {
            let (name, line, chamber, dir) = match c.name() {
                "relief_1" => ("solenoid_1", nodes::LINE_1, nodes::CHAMBER_1, 1.0),
                "relief_2" => ("solenoid_2", nodes::LINE_2, nodes::CHAMBER_2, -1.0),
                _ => continue,
            };
            *c = Box::new(SwitchedOrifice::new(
                name,
                nodes::COMMAND,
                line,
                chamber,
                Area::new(spec.area_m2),
                spec.orifice,
                dir,
            ));
        }
    }

    /// Reads and checks a variant rig value (a `hybrid-variant` file's JSON,
    /// after any `--set`); errors name the JSON path.
    pub fn from_value(v: &serde_json::Value) -> Result<Self, RigError> {
        let r: Self =
            serde_path_to_error::deserialize(v.clone()).map_err(|e| RigError::Invalid {
                path: e.path().to_string(),
                why: e.inner().to_string(),
            })?;
        r.validate()?;
        Ok(r)
    }

    /// The variant's circuit driven by `command` \[V\]: the base rig (a preset,
    /// or a rig file by its path), with the needle opening for the command's
    /// peak speed `K max(u_max / A1, −u_min / A2)` (K the pump's flow gain; the
    /// speed the chapter-8 scenarios command) when the variant sets one per
    /// speed and the command is a table, and the variant's components swapped
    /// in. Any other command keeps the base rig's needle opening.
    pub fn circuit(&self, command: Signal) -> Result<Circuit, RigError> {
        let mut r = self.base_rig(None)?;
        let speed = command.value_range().map(|(lo, hi)| {
            let (hi, lo) = (hi.max(0.0), lo.min(0.0));
            let k = r.pump.gain;
            1e3 * k * (hi / r.cylinder.area_1.si()).max(-lo / r.cylinder.area_2.si())
        });
        self.apply_to_rig(&mut r, speed);
        r.build_with(command, |comps| self.swap_components(comps))
    }

    /// Parses and checks a variant from JSON text; `origin` names it in errors.
    pub fn from_json(text: &str, origin: &str) -> Result<Self, RigError> {
        let v: Self = serde_json::from_str(text).map_err(|e| RigError::Invalid {
            path: origin.into(),
            why: format!("line {} column {}: {e}", e.line(), e.column()),
        })?;
        v.validate()?;
        Ok(v)
    }

    /// Reads a variant file and its base rig.
    pub fn load(path: &Path) -> Result<(WangHybrid, Self), RigError> {
        let origin = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|e| RigError::Invalid {
            path: origin.clone(),
            why: format!("cannot read: {e}"),
        })?;
        let v = Self::from_json(&text, &origin)?;
        let base = v.base_rig(path.parent())?;
        Ok((base, v))
    }

    /// The base rig: a preset, or a rig file (relative paths from `dir`).
    pub fn base_rig(&self, dir: Option<&Path>) -> Result<WangHybrid, RigError> {
        let name = if crate::rig::preset(&self.base).is_some() {
            self.base.clone()
        } else {
            match dir {
                Some(d) if Path::new(&self.base).is_relative() => {
                    d.join(&self.base).display().to_string()
                }
                _ => self.base.clone(),
            }
        };
        let value = crate::rig::load(&name).map_err(|e| RigError::Invalid {
            path: self.name.clone(),
            why: format!("base `{}`: {e}", self.base),
        })?;
        WangHybrid::from_value(&value).map_err(|e| RigError::Invalid {
            path: self.name.clone(),
            why: format!("base `{}` is not a hybrid rig: {e}", self.base),
        })
    }
}
