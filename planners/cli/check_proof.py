"""``cspace check-proof SCENARIO PROOF``: re-check a proof that no path exists (written by
``cspace plan --proof FILE``) with the independent checker :mod:`planners.core.proof_check`
(a Dubins car's reach proof, format ``cspace-dubins-proof/1``: :mod:`planners.core.dubins_check`). Exit 0 valid, 1 invalid (the first failed step named),
2 bad input (a proof asking for more work than any the planner writes among it)."""
from __future__ import annotations

HELP = "re-check a proof that no path exists (from plan --proof)"


def number(text: str) -> float:
    from .plan import number as parse

    return parse(text)


def register(sub) -> None:
    p = sub.add_parser("check-proof", help=HELP,
                       description="Re-check a proof that a rotating robot or a car has no path, independently of "
                                   "the planner that wrote it. Exit 0 valid, 1 invalid, 2 bad input.")
    p.add_argument("scenario", help="the scenario TOML the proof is about")
    p.add_argument("proof", help="the proof (JSON, from cspace plan --planner exact --proof FILE)")
    p.add_argument("--query", type=int, default=0, help="the query the proof is about (0: start and goal)")
    p.add_argument("--space", choices=("se2", "dubins", "reeds-shepp"),
                   help="the space the scenario was planned in, as plan's --space (default: the scenario's)")
    p.add_argument("--turning-radius", type=number, help="a car's turning radius, as plan's --turning-radius "
                                                         "(default: the scenario's)")
    p.set_defaults(run=run)


def run(args) -> int:
    from cspace.io.load import load_scenario

    from ..core.dubins_check import FORMAT as DUBINS_FORMAT, check_dubins_proof
    from ..core.proof_check import TooBig, check_proof, load_proof

    from ..errors import InputError

    scenario = load_scenario(args.scenario, space=args.space,  # bad input: one line, exit 2
                             turning_radius=args.turning_radius)
    count = len(scenario.all_queries())
    if not 0 <= args.query < count:  # a query the scenario does not have is a bad option, not a bad proof
        raise InputError(args.scenario, "--query", f"must be from 0 to {count - 1}, got {args.query}")
    proof = load_proof(args.proof)
    if proof.get("format") == DUBINS_FORMAT:  # a Dubins car's reach proof: its own checker
        check_proof = check_dubins_proof
    try:
        result = check_proof(scenario, proof, args.query)
    except TooBig as exc:  # more work than any proof the planner writes: refused, not judged
        raise InputError(args.proof, "size", f"{exc}: refused") from None
    if result.valid:
        print(f"proof valid: {result.detail}")
        return 0
    print(f"proof invalid: step {result.step}: {result.detail}")
    return 1
