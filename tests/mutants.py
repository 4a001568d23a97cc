"""Mutation check of the energy tests: flip one friction, damping or coupling sign in a copy of the package
and run the dissipation and energy tests against the copy; each mutant must make them fail.

    python3 tests/mutants.py                 # every mutant, a table of killed / survived
    python3 tests/mutants.py stator_friction # one by name

A check that integrates the same forces it audits cannot see such a flip on its own (the audit
closes for a friction whose sign is wrong in both its force and its power); the per-element
dissipation test sees the power's sign, the audit sees a force whose power is booked wrongly.
Each mutant is a text substitution that must match exactly once, so a refactor that moves the
code makes this script fail loudly instead of testing nothing. tests/test_mutants.py runs them.
"""
from __future__ import annotations

import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
TESTS = ("tests/physics/test_dissipation.py", "tests/physics/test_energy.py",
         "tests/physics/flexible/test_flexible_drop.py::test_energy_audit_closes_with_strain_energy",
         "tests/physics/flexible/test_flexible_drop.py::test_stiff_rotor_drop_closes_its_audit_too")


@dataclass(frozen=True)
class Mutant:
    name: str
    path: str
    old: str
    new: str


MUTANTS = (
    Mutant("contact_friction", "physics/contact.py",
           "return mu * f_r * smooth_sign(slip, threshold)",
           "return -mu * f_r * smooth_sign(slip, threshold)"),
    Mutant("kinematic_slip_sleeve_term", "physics/laws/slip_kinematic.py",
           "return et + W * P[P_RJ] - ws * P[P_RS], P[P_VL]",
           "return et + W * P[P_RJ] + ws * P[P_RS], P[P_VL]"),
    Mutant("friction_force_on_rotor", "physics/contact.py",
           "cfx = f_r * nx + f_mu * tx", "cfx = f_r * nx - f_mu * tx"),
    Mutant("friction_torque_on_rotor", "physics/contact.py",
           "-(P[P_RJ] * f_mu)", "(P[P_RJ] * f_mu)"),
    Mutant("friction_torque_on_sleeve", "physics/ball_bearing.py",
           "dws = (P[P_RS] * f_mu - drag_t) / P[P_JS]", "dws = (-P[P_RS] * f_mu - drag_t) / P[P_JS]"),
    Mutant("bearing_drag", "physics/ball_bearing.py",
           "dws = (P[P_RS] * f_mu - drag_t) / P[P_JS]", "dws = (P[P_RS] * f_mu + drag_t) / P[P_JS]"),
    Mutant("massless_sleeve_friction", "physics/laws/slip_kinematic.py",
           "return (et + W * P[P_RJ]) / P[P_RS], et + W * P[P_RJ], P[P_VL]",
           "return (et + W * P[P_RJ]) / P[P_RS], -(et + W * P[P_RJ]), P[P_VL]"),
    Mutant("contact_damping", "physics/laws/power_law.py",
           "f = elastic + step(delta, 0.0, 0.0, d, c_max) * delta_dot",
           "f = elastic - step(delta, 0.0, 0.0, d, c_max) * delta_dot"),
    Mutant("hunt_crossley_damping", "physics/laws/hertz_line.py",
           "f = elastic * (1.0 + chi * delta_dot)", "f = elastic * (1.0 - chi * delta_dot)"),
    Mutant("ball_bearing_damping", "physics/ball_bearing.py",
           "bfy = -qy - P[P_CB] * uvy", "bfy = -qy + P[P_CB] * uvy"),
    Mutant("linear_bearing_damping", "physics/ball_bearing.py",
           "bfy = -P[P_KLIN] * uy - P[P_CB] * uvy", "bfy = -P[P_KLIN] * uy + P[P_CB] * uvy"),
    Mutant("support_damping", "physics/support.py",
           "-K_s * hy - C_s * vy", "-K_s * hy + C_s * vy"),
    Mutant("stator_friction", "physics/stator.py",
           "f_mu = mu * f_n * smooth_sign(slip, v_l)", "f_mu = -mu * f_n * smooth_sign(slip, v_l)"),
    Mutant("stator_damping", "physics/stator.py",
           "f_n = elastic + c * ddelta", "f_n = elastic - c * ddelta"),
    Mutant("stator_mount_damping", "physics/stator.py",
           "(-sfy - k * qy - c * qvy) / m", "(-sfy - k * qy + c * qvy) / m"),
    Mutant("stator_mount_reaction", "physics/stator.py",
           "(-sfy - k * qy - c * qvy) / m", "(sfy - k * qy - c * qvy) / m"),
    # the flexible rotor (physics/flexible_rotor.py): structural damping, the gyroscopic
    # couplings of the elastic modes, and the projection of the station forces on the modes
    Mutant("flexible_structural_damping", "physics/flexible_rotor.py",
           "ax = qx - P[w2 + j] * ex - P[damp + j] * vx", "ax = qx - P[w2 + j] * ex + P[damp + j] * vx"),
    Mutant("flexible_mode_gyroscopics", "physics/flexible_rotor.py",
           "ax -= Omega * gx", "ax += Omega * gx"),
    Mutant("flexible_tilt_coupling", "physics/rotor.py",
           "Ma -= spin * cy", "Ma += spin * cy"),
    Mutant("flexible_station_forces", "physics/flexible_rotor.py",
           "qy += sh * aux[a_force + 2 * s + 1]", "qy -= sh * aux[a_force + 2 * s + 1]"),
)


def copy_tree(dest: Path) -> None:
    """The checkout's tracked and untracked (not ignored) files, as they are on disk."""
    files = subprocess.run(["git", "ls-files", "-co", "--exclude-standard"], cwd=ROOT, check=True,
                           capture_output=True, text=True).stdout.split()
    for f in files:
        src = ROOT / f
        if src.is_file() and not f.startswith(("docs/", "agents/policies/")):
            (dest / f).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(src, dest / f)


def apply(mutant: Mutant, root: Path) -> None:
    path = root / mutant.path
    text = path.read_text()
    count = text.count(mutant.old)
    if count != 1:
        raise SystemExit(f"mutant {mutant.name}: {mutant.old!r} occurs {count} times in "
                         f"{mutant.path} (must be once): update tests/mutants.py")
    path.write_text(text.replace(mutant.old, mutant.new))


def run(mutant: Mutant, tests=TESTS) -> tuple[bool, str]:
    """(killed, the first failing test's line) for one mutant, run in a fresh copy."""
    with tempfile.TemporaryDirectory(prefix=f"mutant-{mutant.name}-") as tmp:
        root = Path(tmp)
        copy_tree(root)
        apply(mutant, root)
        proc = subprocess.run([sys.executable, "-m", "pytest", "-x", "-q", "-p", "no:xdist",
                               "-p", "no:cacheprovider", "-o", "addopts=", *tests],
                              cwd=root, capture_output=True, text=True)
        failed = [ln for ln in proc.stdout.splitlines() if ln.startswith("FAILED")]
        # killed: a test failed (exit 1 with a FAILED line); an error collecting or running the
        # copy (exit 2 or 1 with ERROR lines only) says nothing about the checks
        killed = proc.returncode == 1 and bool(failed)
        return killed, (failed[0] if failed else proc.stdout.strip().splitlines()[-1])


def main(argv: list[str]) -> int:
    chosen = [m for m in MUTANTS if not argv or m.name in argv]
    unknown = set(argv) - {m.name for m in MUTANTS}
    if unknown:
        raise SystemExit(f"unknown mutant(s) {sorted(unknown)}; known: {[m.name for m in MUTANTS]}")
    survived = 0
    print(f"{'mutant':28} {'result':9} {'s':>5}  first failing test")
    for m in chosen:
        t0 = time.perf_counter()
        killed, line = run(m)
        survived += not killed
        print(f"{m.name:28} {'killed' if killed else 'SURVIVED':9} {time.perf_counter() - t0:5.0f}  "
              f"{line}", flush=True)
    print(f"{len(chosen) - survived} of {len(chosen)} mutants killed")
    return 1 if survived else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
