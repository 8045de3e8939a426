//! The energy ledger of one run: energy in, out to the load, each loss by
//! component, change in storage, and the balance error.
//!
//! The assembler integrates five quadratures per component
//! ([`Circuit::set_ledger`]): ∫source, ∫dissipated, ∫storage, ∫load dt \[J\],
//! and ∫moved dt, the stored energy carried by moving walls
//! ([`PowerTerms::moved`](hydrocyl_system::circuit::PowerTerms::moved)).
//! Over a window `[t0, t1]` of output samples the ledger takes their
//! differences and closes
//!
//! ```text
//! E_in = E_load + Σ E_loss + ΔE_stored          (balance error = residual / E_in)
//! ```
//!
//! (where no energy comes in over the window, the errors are fractions of
//! the largest other term instead: [`Ledger::reference_j`]).
//!
//! Two storage figures are kept: the integrated storage power (what closes the
//! balance) and the change of the stored energy recomputed from the states at
//! the window's ends (`½ V p²/B` per volume, `½ (m + c) v²` for the load with
//! the friction's acceleration term `c` as added mass, `½ σ0 z²` per bristle).
//! They differ by what the chambers' moving walls carry
//! ([`Ledger::moving_walls_j`]); what is left is [`Ledger::storage_error`],
//! an independent check of the integration. An event that edits a state (a
//! plastic impact at a stroke end) moves the stored energy it removes to the
//! component's losses (the impact's loss is booked under the mass).

use crate::error::EnergyError;
use hydrocyl_system::circuit::{LEDGER_TERMS, LEDGER_TERM_NAMES};
use hydrocyl_system::run::Run;
use hydrocyl_system::Circuit;
use serde::Serialize;
use serde_json::{json, Map, Value};

/// One named energy \[J\] over the window.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Term {
    /// Name: the component's (`needle_valve`, `pilot_valve`, ...).
    pub name: String,
    /// Energy over the window \[J\].
    pub energy_j: f64,
}

/// One component's integrated ledger quadratures over the window \[J\], in
/// the order of [`LEDGER_TERM_NAMES`] (source, dissipated, storage, load,
/// moved), none left out.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ComponentTerms {
    /// The component's name.
    pub name: String,
    /// Its terms over the window \[J\].
    pub energy_j: [f64; LEDGER_TERMS],
}

/// The ledger of one run over one window.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Ledger {
    /// Window start and end \[s\].
    pub window_s: (f64, f64),
    /// Energy brought in by sources (the supply, the pump's hydraulic
    /// power `(p_A − p_B) Q`) \[J\].
    pub energy_in_j: f64,
    /// Sources by component \[J\].
    pub sources: Vec<Term>,
    /// Work done on the external load (gravity: the potential energy gained,
    /// `∫ F_ext v dt`) \[J\].
    pub load_out_j: f64,
    /// The cylinder's mechanical output of eq 8.7, `∫ v (p1 A1 − p2 A2) dt`
    /// \[J\]: friction, load and kinetic energy together (what the thesis
    /// calls output).
    pub cylinder_out_j: f64,
    /// Energy turned into heat, by component \[J\] (zero terms left out).
    pub losses: Vec<Term>,
    /// Integrated storage power by component (fluid compression, kinetic,
    /// bristle) \[J\] (zero terms left out).
    pub storage: Vec<Term>,
    /// Change of the stored energy recomputed from the end states \[J\].
    pub stored_change_from_states_j: f64,
    /// The part of that change the storage power does not contain: the
    /// energy density of each chamber times its volume change, `∫ ½ p²/B dV`
    /// without entrained air \[J\]. The linear fluid model stores
    /// `p V/B dp` (what closes the balance); its stored energy as a function
    /// of the state, `½ V p²/B`, also moves with the walls.
    pub moving_walls_j: f64,
    /// The energy [`Ledger::error`] and [`Ledger::storage_error`] are
    /// fractions of \[J\]: `energy_in_j` where energy comes in; where none
    /// does over the window (a volume discharging to tank, a mass braking,
    /// a hydraulic spring swinging), the largest of the balance's other
    /// terms (the load's, the losses' and the storage's, each summed in
    /// magnitude); 0 where nothing moved (the errors are then in J).
    pub reference_j: f64,
    /// Balance residual `E_in − E_load − Σ E_loss − Σ storage` as a fraction
    /// of [`Ledger::reference_j`] (of `E_in` where energy comes in) \[-\].
    pub error: f64,
    /// `(Σ storage + moving_walls − stored_change_from_states)` as a fraction
    /// of [`Ledger::reference_j`] \[-\]: the integration's error alone.
    pub storage_error: f64,
    /// The components whose model form does not conserve energy
    /// ([`Component::energy_consistent`](hydrocyl_system::Component::energy_consistent)):
    /// with any here, `error` and `storage_error` measure the form, not the
    /// bookkeeping or the integration, and need not be small.
    pub not_energy_consistent: Vec<String>,
    /// Every component's quadratures over the window, in circuit order (the
    /// lists above are built from these).
    pub components: Vec<ComponentTerms>,
}

impl Ledger {
    /// Sum of the losses \[J\].
    pub fn total_loss_j(&self) -> f64 {
        self.losses.iter().map(|t| t.energy_j).sum()
    }

    /// Sum of the integrated storage \[J\].
    pub fn total_storage_j(&self) -> f64 {
        self.storage.iter().map(|t| t.energy_j).sum()
    }

    /// The efficiency of eqs 8.1–8.7: cylinder output over energy in \[-\];
    /// NaN (`null` in [`Ledger::to_json`]) where no energy comes in over
    /// the window.
    pub fn efficiency(&self) -> f64 {
        if self.energy_in_j > 0.0 {
            self.cylinder_out_j / self.energy_in_j
        } else {
            f64::NAN
        }
    }

    /// The balance residual `E_in − E_load − Σ E_loss − Σ storage` \[J\]
    /// ([`Ledger::error`] times [`Ledger::reference_j`]).
    pub fn closure_j(&self) -> f64 {
        self.energy_in_j - self.load_out_j - self.total_loss_j() - self.total_storage_j()
    }

    /// The storage check `Σ storage + moving_walls − ΔE_stored(states)`
    /// \[J\] ([`Ledger::storage_error`] times [`Ledger::reference_j`]).
    pub fn storage_check_j(&self) -> f64 {
        self.total_storage_j() + self.moving_walls_j - self.stored_change_from_states_j
    }

    /// The sum over the components of each of the [`LEDGER_TERM_NAMES`]
    /// \[J\].
    pub fn totals_j(&self) -> [f64; LEDGER_TERMS] {
        let mut t = [0.0; LEDGER_TERMS];
        for c in &self.components {
            for (s, e) in t.iter_mut().zip(c.energy_j) {
                *s += e;
            }
        }
        t
    }

    /// The ledger as one JSON object, what `hydrocyl simulate --ledger`
    /// writes and Python's `run.ledger` is (the same keys): every energy in
    /// J under a key ending `_j` (in an object under such a key, each value),
    /// times in s under `_s`, fractions of `reference_j` (the energy in,
    /// where energy comes in) dimensionless (the `units` entry says so):
    ///
    /// * `components_j`: each component's quadratures by
    ///   [`LEDGER_TERM_NAMES`], `totals_j` their sums;
    /// * `energy_in_j`, `sources_j`, `load_out_j`, `cylinder_out_j`,
    ///   `losses_j`, `storage_j` (by component, negligible terms left out),
    ///   `stored_change_from_states_j`, `moving_walls_j`;
    /// * `closure_j` ([`Ledger::closure_j`]) and `closure_relative` (=
    ///   `error`), `storage_check_j` ([`Ledger::storage_check_j`]) and
    ///   `storage_check_relative` (= `storage_error`), `reference_j`
    ///   ([`Ledger::reference_j`]), `efficiency` (`null` where no energy
    ///   comes in);
    /// * `not_energy_consistent`: the components over which the closure
    ///   measures the model form, not the bookkeeping.
    pub fn to_json(&self) -> Value {
        let by_name = |ts: &[Term]| -> Value {
            Value::Object(
                ts.iter()
                    .map(|t| (t.name.clone(), json!(t.energy_j)))
                    .collect::<Map<_, _>>(),
            )
        };
        let named = |v: &[f64; LEDGER_TERMS]| -> Value {
            Value::Object(
                LEDGER_TERM_NAMES
                    .iter()
                    .zip(v)
                    .map(|(n, e)| (n.to_string(), json!(e)))
                    .collect::<Map<_, _>>(),
            )
        };
        let components: Map<_, _> = self
            .components
            .iter()
            .map(|c| (c.name.clone(), named(&c.energy_j)))
            .collect();
        json!({
            "units": {
                "_j": "J (every value under a key ending _j)",
                "_s": "s",
                "closure_relative": REFERENCED,
                "storage_check_relative": REFERENCED,
                "error": REFERENCED,
                "storage_error": REFERENCED,
                "efficiency": "1 (cylinder_out_j / energy_in_j; null where no energy comes in)",
            },
            "window_s": [self.window_s.0, self.window_s.1],
            "term_names": LEDGER_TERM_NAMES,
            "components_j": components,
            "totals_j": named(&self.totals_j()),
            "energy_in_j": self.energy_in_j,
            "sources_j": by_name(&self.sources),
            "load_out_j": self.load_out_j,
            "cylinder_out_j": self.cylinder_out_j,
            "losses_j": by_name(&self.losses),
            "storage_j": by_name(&self.storage),
            "stored_change_from_states_j": self.stored_change_from_states_j,
            "moving_walls_j": self.moving_walls_j,
            "closure_j": self.closure_j(),
            "closure_relative": self.error,
            "storage_check_j": self.storage_check_j(),
            "storage_check_relative": self.storage_error,
            "error": self.error,
            "storage_error": self.storage_error,
            "reference_j": self.reference_j,
            "efficiency": self.efficiency(),
            "not_energy_consistent": self.not_energy_consistent,
        })
    }

    /// A loss by name \[J\] (0 when absent).
    pub fn loss(&self, name: &str) -> f64 {
        self.losses
            .iter()
            .filter(|t| t.name == name)
            .map(|t| t.energy_j)
            .sum()
    }

    /// Every term by name, for reports: `in.<source>`, `load`, `loss.<c>`,
    /// `storage.<c>` \[J\].
    pub fn named_terms(&self) -> Vec<(String, f64)> {
        let mut v: Vec<(String, f64)> = self
            .sources
            .iter()
            .map(|t| (format!("in.{}", t.name), t.energy_j))
            .collect();
        v.push(("load".into(), self.load_out_j));
        v.extend(
            self.losses
                .iter()
                .map(|t| (format!("loss.{}", t.name), t.energy_j)),
        );
        v.extend(
            self.storage
                .iter()
                .map(|t| (format!("storage.{}", t.name), t.energy_j)),
        );
        v
    }
}

/// Where the rod lives in the circuit: the mechanical nodes the cylinders
/// drive and the components on them whose powers make the cylinders'
/// output (eq 8.7).
#[derive(Clone, Debug, PartialEq)]
pub struct RodSide {
    /// The mechanical nodes, comma-separated, as the netlist names them (a
    /// named node, `rod` on the hybrid preset, or after a port on it,
    /// `load.rod` on the valve preset).
    pub node: String,
    /// The components on the rods other than the cylinders: the masses and
    /// the friction laws (`load`, `friction` in the presets).
    pub components: Vec<String>,
}

impl RodSide {
    /// The rod side of `circuit`, found by its connections, whatever the
    /// components are named: every mechanical node an actuator
    /// ([`Circuit::is_actuator`]: a cylinder, a bench's piston) drives, and
    /// every other component attached to one of them (masses, friction
    /// laws). Empty where the circuit has no actuator.
    pub fn of(circuit: &Circuit) -> Self {
        let n = circuit.components().count();
        let mut nodes: Vec<&str> = Vec::new();
        for i in (0..n).filter(|&i| circuit.is_actuator(i)) {
            for m in circuit.mechanical_nodes(i) {
                if !nodes.contains(&m.as_str()) {
                    nodes.push(m);
                }
            }
        }
        let components = circuit
            .components()
            .enumerate()
            .filter(|(i, _)| {
                !circuit.is_actuator(*i)
                    && circuit
                        .mechanical_nodes(*i)
                        .iter()
                        .any(|m| nodes.contains(&m.as_str()))
            })
            .map(|(_, c)| c.name().to_string())
            .collect();
        Self {
            node: nodes.join(", "),
            components,
        }
    }
}

/// What the relative figures of [`Ledger::to_json`] are fractions of.
const REFERENCED: &str =
    "1 (fraction of reference_j: energy_in_j where energy comes in, else the largest other term)";

/// Energy (magnitudes) below this fraction of [`Ledger::reference_j`] is
/// left out of the term lists as zero.
const NEGLIGIBLE: f64 = 1e-12;

/// The ledger of `run` (made with `RunOptions::ledger` on) over output
/// samples `k0..=k1`. `circuit` is the one the run was made on.
pub fn ledger(
    circuit: &Circuit,
    run: &Run,
    k0: usize,
    k1: usize,
    rod: &RodSide,
) -> Result<Ledger, EnergyError> {
    let n_comp = circuit.components().count();
    let off = circuit.ledger_offset();
    if run.dim != off + LEDGER_TERMS * n_comp {
        return Err(EnergyError::Ledger(format!(
            "the run has {} entries per state, the circuit with its ledger {}: run with `ledger: true`",
            run.dim,
            off + LEDGER_TERMS * n_comp
        )));
    }
    if !(k0 < k1 && k1 < run.time.len()) {
        return Err(EnergyError::Ledger(format!(
            "window samples {k0}..{k1} not inside the run's {} samples",
            run.time.len()
        )));
    }
    let (x0, x1) = (run.state(k0), run.state(k1));
    let d = |i: usize, term: usize| {
        let k = off + LEDGER_TERMS * i + term;
        x1[k] - x0[k]
    };
    let mut sources = Vec::new();
    let mut components = Vec::new();
    let mut losses = Vec::new();
    let mut storage = Vec::new();
    let (mut e_in, mut e_load, mut e_cyl, mut e_moved) = (0.0, 0.0, 0.0, 0.0);
    let names: Vec<String> = circuit.components().map(|c| c.name().to_string()).collect();
    for (i, name) in names.iter().enumerate() {
        let terms: [f64; LEDGER_TERMS] = std::array::from_fn(|term| d(i, term));
        components.push(ComponentTerms {
            name: name.clone(),
            energy_j: terms,
        });
        let [src, diss, sto, load, moved] = terms;
        e_moved += moved;
        e_in += src;
        e_load += load;
        if rod.components.contains(name) {
            e_cyl += diss + sto + load;
        }
        let push = |v: &mut Vec<Term>, e: f64| {
            v.push(Term {
                name: name.clone(),
                energy_j: e,
            })
        };
        if src != 0.0 {
            push(&mut sources, src);
        }
        if diss != 0.0 {
            push(&mut losses, diss);
        }
        if sto != 0.0 {
            push(&mut storage, sto);
        }
    }
    if !e_in.is_finite() {
        return Err(EnergyError::Ledger(format!(
            "energy in over the window is {e_in} J"
        )));
    }
    let reference = reference_energy(e_in, e_load, &losses, &storage);
    let tiny = NEGLIGIBLE * reference;
    losses.retain(|t| t.energy_j.abs() > tiny);
    storage.retain(|t| t.energy_j.abs() > tiny);
    let sum_loss: f64 = losses.iter().map(|t| t.energy_j).sum();
    let sum_sto: f64 = storage.iter().map(|t| t.energy_j).sum();
    let fraction = |e: f64| if reference > 0.0 { e / reference } else { e };
    let stored = |k: usize| stored_energy(circuit, run.time[k], run.state(k));
    let from_states = stored(k1) - stored(k0);
    Ok(Ledger {
        window_s: (run.time[k0], run.time[k1]),
        energy_in_j: e_in,
        sources,
        load_out_j: e_load,
        cylinder_out_j: e_cyl,
        losses,
        storage,
        stored_change_from_states_j: from_states,
        moving_walls_j: e_moved,
        reference_j: reference,
        error: fraction(e_in - e_load - sum_loss - sum_sto),
        storage_error: fraction(sum_sto + e_moved - from_states),
        not_energy_consistent: circuit
            .components()
            .filter(|c| !c.energy_consistent())
            .map(|c| c.name().to_string())
            .collect(),
        components,
    })
}

/// The energy a ledger's relative figures are fractions of
/// ([`Ledger::reference_j`]): the energy in where energy comes in, else the
/// largest of the balance's other terms (what the load took, the losses, the
/// storage, each summed in magnitude); 0 where nothing moved at all.
fn reference_energy(e_in: f64, e_load: f64, losses: &[Term], storage: &[Term]) -> f64 {
    if e_in > 0.0 {
        return e_in;
    }
    let magnitude = |ts: &[Term]| ts.iter().map(|t| t.energy_j.abs()).sum::<f64>();
    e_in.abs()
        .max(e_load.abs())
        .max(magnitude(losses))
        .max(magnitude(storage))
}

/// The ledger between two states of a run made with `RunOptions::ledger`
/// on: `(t0, x0)` and `(t1, x1)`, full state vectors (the ledger's
/// quadratures included), e.g. the first and last output of a streamed run
/// that keeps no states between. `circuit` is the rig's, with its ledger on
/// ([`Circuit::set_ledger`]); the result is [`ledger`]'s over those two
/// samples of the whole run.
pub fn ledger_between(
    circuit: &Circuit,
    (t0, x0): (f64, &[f64]),
    (t1, x1): (f64, &[f64]),
    rod: &RodSide,
) -> Result<Ledger, EnergyError> {
    if x0.len() != x1.len() {
        return Err(EnergyError::Ledger(format!(
            "the two states have {} and {} entries",
            x0.len(),
            x1.len()
        )));
    }
    let run = Run {
        time: vec![t0, t1],
        states: [x0, x1].concat(),
        dim: x0.len(),
        ..Run::default()
    };
    ledger(circuit, &run, 0, 1, rod)
}

/// Energy stored in the circuit at `(t, x)` \[J\]: every component's
/// `stored` (the mass's and the bench drive's `½ (m + c) v²` with the
/// friction's acceleration term `c` as added mass).
pub fn stored_energy(circuit: &Circuit, t: f64, x: &[f64]) -> f64 {
    circuit.power_terms(t, x).iter().map(|p| p.stored).sum()
}

/// `∫ y dt` by the trapezoidal rule over samples `k0..=k1` \[unit of y · s\].
pub fn trapezoid(time: &[f64], y: &[f64], k0: usize, k1: usize) -> f64 {
    (k0..k1)
        .map(|k| 0.5 * (y[k] + y[k + 1]) * (time[k + 1] - time[k]))
        .sum()
}
