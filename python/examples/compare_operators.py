"""Run the wall scenario with every t-conorm of the catalogue and print, per operator, the holes
(truly occupied voxels the map calls free), the spurious occupied voxels (where the truth is
unobservable) and the occupied F1, beside the log-odds and alpha-cut baselines.

    python compare_operators.py                 # the wall scenario at 0.2 m
    python compare_operators.py --res 0.1 --scenario random --pairs 50
"""

import argparse
import time

import fuzzyvox


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenario", choices=["wall", "random"], default="wall")
    parser.add_argument("--pairs", type=int, default=100, help="pairs of the random flight")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--res", type=float, default=0.2)
    args = parser.parse_args()

    if args.scenario == "wall":
        scenario = fuzzyvox.Scenario.wall()
    else:
        scenario = fuzzyvox.Scenario.random(pairs=args.pairs, seed=args.seed)
    operators = fuzzyvox.operators()
    started = time.perf_counter()
    experiment = fuzzyvox.run_experiment(scenario, res=args.res, operators=operators, seed=args.seed)
    seconds = time.perf_counter() - started
    report = experiment.report
    print(
        f"{scenario.name} scenario, {report['pairs']} pairs at {args.res} m, "
        f"{report['truth_occupied']} truly occupied voxels; {seconds:.1f} s"
    )
    print(f"{'map':<26} {'holes':>7} {'spurious':>9} {'F1':>7}")
    # The experiment names each extra fuzzy map after its t-conorm (`fuzzy:maximum` for the
    # operator `minimum`); label the rows with the operator as it was given.
    by_operator = {
        m.operator: name for name, m in experiment.maps.items() if name.startswith("fuzzy:")
    }
    rows = [("logodds", "logodds"), ("alpha", "alpha")]
    rows += [(f"fuzzy {op}", by_operator[op]) for op in operators]
    for label, name in rows:
        m = report["maps"][name]
        print(f"{label:<26} {m['holes']:>7} {m['spurious_unknown']:>9} {m['occupied_f1']:>7.3f}")


if __name__ == "__main__":
    main()
