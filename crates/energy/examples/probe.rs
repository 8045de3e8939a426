//! Scratch probe: runs scenarios once and prints the ledger.
use hydrocyl_energy::scenario::*;
use hydrocyl_energy::variant::HybridVariant;
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let plan = Plan::default();
    let mut drives = vec![("valve".to_string(), Drive::wang_valve_c10().unwrap()), ("hybrid".to_string(), Drive::wang_hybrid())];
    for f in ["wang-hybrid-solenoid", "wang-hybrid-needle", "wang-hybrid-improved"] {
        let (b, v) = HybridVariant::load(std::path::Path::new(&format!("fixtures/rigs/{f}.json"))).unwrap();
        drives.push((v.name.clone(), Drive::Hybrid(Box::new(b), Some(v))));
    }
    for (name, d) in &drives {
        for sc in scenarios_for(name) {
            if args.len() > 1 && !sc.label().contains(&args[1]) { continue; }
            match run_scenario(d, &sc, &plan) {
                Ok(o) => {
                    println!("{:40} eff {:6.2}% thesis {:?} err {:.2e} sto_err {:.2e} wall {:.2}s in {:.1} J out {:.1} J load {:.1} peaks {:.1?}", sc.label(), 100.0*o.efficiency, o.thesis_efficiency.map(|e| e*100.0), o.ledger.error, o.ledger.storage_error, o.wall_s, o.ledger.energy_in_j, o.ledger.cylinder_out_j, o.ledger.load_out_j, o.peak_speeds_mm_s);
                    for t in &o.ledger.losses { println!("    loss {:24} {:10.2} J", t.name, t.energy_j); }
                }
                Err(e) => println!("{}: ERROR {e}", sc.label()),
            }
        }
    }
}
