"""Writes the chapter-9 rig files (fixtures/rigs/wang-hybrid-{solenoid,needle,improved,servo-needle,
closed-loop}.json) from fixtures/rigs/wang-hybrid.json, so that they differ from it only where
docs/hybrid.md says. Run from the repository root after the base rig changes:

    python3 xtask/chapter9_rigs.py

The shipped needle openings and servo gains are the chapter-9 optimiser's results at +-50 mm/s
(`cargo xtask energy`, the row "chapter9-choices" of target/energy/energy.json): update NEEDLE_50 and
NEEDLE_SOL_50 from there when the base rig changes (`cargo xtask validate --only chapter9` checks the
needle file against the optimiser)."""
import copy
import json
base = json.load(open('fixtures/rigs/wang-hybrid.json'))
NEEDLE_50 = 2.808624803859787e-06
NEEDLE_SOL_50 = 1.6589642083026653e-06
# proportional law through the 50 mm/s optimum: g = (A/v) K/A1, (A/v) K/A2
SERVO_GP = NEEDLE_SOL_50/0.05*1.07e-05/0.0008042
SERVO_GN = NEEDLE_SOL_50/0.05*1.07e-05/0.00055

def without(d, comps, outs):
    for c in comps: del d['components'][c]
    d['connections'] = [[x for x in c if x.split('.')[0] not in comps] for c in d['connections']]
    for o in outs: del d['outputs'][o]

def order(d):
    return {k: d[k] for k in ['kind','name','description','components','connections','outputs']}

def write(d, suffix):
    with open(f'fixtures/rigs/wang-hybrid-{suffix}.json', 'w') as f:
        json.dump(order(d), f, indent=2)
        f.write('\n')

def solenoid(d):
    without(d, ['relief_1','relief_2','pilot_valve'], ['relief_1_flow','relief_2_flow','pilot_spool','return_flow_1','return_flow_2'])
    comps = d['components']
    new = {}
    for k, v in comps.items():
        new[k] = v
        if k == 'check_2':
            new['four_way'] = {"type": "solenoid_four_way", "area_supply": 1.5e-5, "area_return": 1.5e-5,
                "threshold": 0.05, "time_constant": 0.01,
                "orifice": {"cd": 0.65, "density": 900.0, "dp_transition": 1000.0}, "initial": {"spool": 0.0}}
    d['components'] = new
    for c in d['connections']:
        if c[0] == 'pump_command': c.append('four_way.command')
        if c[0] == 'pump_line_1': c.append('four_way.P1')
        if c[0] == 'pump_line_2': c.append('four_way.P2')
        if c[0] == 'chamber_1': c.append('four_way.A')
        if c[0] == 'chamber_2': c.append('four_way.B')
        if c[0] == 'return_port': c.insert(2, 'four_way.T')
    d['outputs']['spool'] = 'four_way.spool'

SOL_DESC = ("The solenoid four-way valve (`solenoid_four_way`: command-switched, closed centre, "
  "spool time constant 10 ms, 1.5e-5 m^2 per path, about 20 L/min at 5 bar) replaces the pilot-shifted DDDC valve; "
  "it connects the fed pump line straight to its chamber, so relief valves 1 and 2 are removed (thesis section 9.2).")
NEEDLE_DESC = ("`needle_valve.area` is the parameter the chapter-9 study sets per speed (hydrocyl_studies::chapter9::needle, docs/hybrid.md); "
  "the file ships the optimiser's opening for +-50 mm/s.")

# (a) solenoid
d = copy.deepcopy(base); d['name'] = 'wang-hybrid-solenoid'
d['description'] = "wang-hybrid with " + SOL_DESC[0].lower() + SOL_DESC[1:]
solenoid(d); write(d, 'solenoid')
# (b) needle
d = copy.deepcopy(base); d['name'] = 'wang-hybrid-needle'
d['description'] = "wang-hybrid with the needle (NCCC) opening chosen per speed (thesis sections 8.2, 9.2): " + NEEDLE_DESC
d['components']['needle_valve']['area'] = NEEDLE_50
write(d, 'needle')
# (a)+(b)
d = copy.deepcopy(base); d['name'] = 'wang-hybrid-improved'
d['description'] = "Both improvements of section 9.2. " + SOL_DESC + " " + NEEDLE_DESC
solenoid(d); d['components']['needle_valve']['area'] = NEEDLE_SOL_50
write(d, 'improved')
# servo needle
d = copy.deepcopy(base); d['name'] = 'wang-hybrid-servo-needle'
solenoid(d)
nv = d['components']['needle_valve']
d['components']['needle_valve'] = {"type": "servo_needle_valve", "area_min": 0.0, "area_max": 3.0e-5,
   "gain_positive": SERVO_GP, "gain_negative": SERVO_GN, "effective_factor": nv['effective_factor'],
   "orifice": nv['orifice'], "reverse_check": nv['reverse_check']}
for c in d['connections']:
    if c[0] == 'pump_command': c.append('needle_valve.command')
d['outputs']['needle_opening'] = 'needle_valve.opening'
d['description'] = ("wang-hybrid-solenoid with a servo needle valve (`servo_needle_valve`) whose opening follows the velocity command "
  "(thesis section 9.2): Avn = g+ u+ + g- u-, the gains the chapter-9 study's fit to the optimiser's opening for this drive at +-50 mm/s "
  "(hydrocyl_studies::chapter9::servo, docs/hybrid.md). " + SOL_DESC)
write(d, 'servo-needle')
# closed loop
d = copy.deepcopy(base); d['name'] = 'wang-hybrid-closed-loop'
comps = {"reference": {"type": "command_input"},
         "controller": {"type": "position_controller", "gain": 600.0, "integral_time": 0.0, "bias": 0.0,
                        "output_min": -10.0, "output_max": 10.0}}
del d['components']['command']
comps.update(d['components']); d['components'] = comps
d['connections'] = [c for c in d['connections'] if c[0] != 'pump_command']
d['connections'].insert(0, ["position_reference", "reference.out", "controller.reference"])
d['connections'].insert(1, ["pump_command", "controller.command", "pump.command"])
for c in d['connections']:
    if c[0] == 'rod': c.append('controller.rod')
d['outputs']['command'] = 'controller.command'
d['outputs'] = {"reference": "reference.command", **d['outputs']}
d['description'] = ("wang-hybrid in closed loop (thesis section 9.2): a position P controller on the servomotor, "
  "u = clip(Kp (r - x), -10, 10) V with Kp = 600 V/m (loop crossover Kp K / A1 = 8 rad/s, a sixth of the pump's 47.6 rad/s); "
  "the run's input is the position reference [m].")
write(d, 'closed-loop')
