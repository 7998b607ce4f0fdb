"""Command line: ``python -m pre <subcommand>``.

Subcommands:
  geometry     a geometry spec (TOML) -> geometry file and case file
  geometry3d   a spec of 3D bodies (TOML) -> geometry file of volumes and case file
  cases        write cases/<scene>/geometry.h5 and every study's namelist
  hertz        a Hertz case for any cylinder (radius, E, nu, indentation; mesh, layout)
  hertz3d      the 3D Hertz scene: a ball octant pressed on a rigid plane or a block (issue 42)
  ironing3d    the 3D ironing scene: a rigid sphere pressed into a slab and slid (issue 42)
  cattaneo3d   the 3D Cattaneo-Mindlin scene: a half ball pressed on a rigid plane, sheared (issue 42)
  cattaneo     a Cattaneo-Mindlin case (a half cylinder pressed, then sheared)
  refine       a result: its case refined at the contact zone; a case: the splipy dump
  plot-layout  draw a body's control nets and contact basis functions
  figures      write the figures of docs/figures/
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any


def _from_spec(command: str, write: Callable[[], Any], spec: str) -> Any:
    """Run ``write`` (a spec's writer); a bad spec is one line on stderr naming
    ``python -m pre COMMAND`` and None."""
    from .spec import SpecError

    try:
        return write()
    except (SpecError, FileNotFoundError, OSError) as err:
        print(f"python -m pre {command}: {err}", file=sys.stderr)
    except (ValueError, TypeError, KeyError, IndexError, ArithmeticError, RuntimeError) as err:
        # what the checks of spec_check.py and the builders did not name (a spline
        # library's own refusal): still one line, still bad input
        print(f"python -m pre {command}: {spec}: {type(err).__name__}: {err}", file=sys.stderr)
    return None


def _report(command: str, spec: str, done: Any) -> int:
    """What a spec's writer did (a :class:`pre.spec.SpecOutcome`), as ``python -m pre
    COMMAND`` prints it: the files written, kept, or the differences (exit 2)."""
    if done.stale:
        print(f"python -m pre {command}: {done.case} and {done.geometry.name} differ from what "
              f"{spec} gives now:", file=sys.stderr)
        for line in done.changes:
            print(f"  {line}", file=sys.stderr)
        print("nothing written; --force writes both from the spec (the case file's own values "
              "listed above are then replaced)", file=sys.stderr)
        return 2
    if not done.written:
        print(f"kept {done.geometry} and {done.case} (up to date with {spec})")
        return 0
    print(f"wrote {done.geometry}")
    print(f"wrote {done.case}")
    if done.changes:
        print("replaced (case file or geometry -> spec):")
        for line in done.changes:
            print(f"  {line}")
    return 0


def _cmd_geometry(args: argparse.Namespace) -> int:
    from .spec import write_from_spec

    done = _from_spec("geometry", lambda: write_from_spec(args.spec, args.out, args.force), args.spec)
    return 2 if done is None else _report("geometry", args.spec, done)


def _cmd_geometry3d(args: argparse.Namespace) -> int:
    from .spec3d import write_from_spec3d

    done = _from_spec("geometry3d", lambda: write_from_spec3d(args.spec, args.out, args.force), args.spec)
    return 2 if done is None else _report("geometry3d", args.spec, done)


def _cmd_cases(args: argparse.Namespace) -> int:
    from .cases import write_cases

    written = write_cases(args.out)
    print(f"wrote {len(written)} files under {args.out}")
    return 0


def _cmd_cattaneo(args: argparse.Namespace) -> int:
    from .cattaneo import CattaneoCaseError, CattaneoScene, write_cattaneo
    from .files import OutputError

    scene = CattaneoScene(radius=args.radius, youngs_modulus=args.youngs_modulus,
                          poisson_ratio=args.poisson_ratio, indentation=args.indentation,
                          friction=args.friction, press_friction=args.press_friction,
                          elements_per_a=args.elements_per_a, master=args.master, method=args.method,
                          layout=args.layout, shear=args.shear, press_steps=args.steps[0],
                          shear_steps=args.steps[1], penalty_normal=args.penalty_normal)
    try:
        case = write_cattaneo(scene, args.out, force=args.force)
    except (CattaneoCaseError, OutputError, OSError) as err:
        print(f"python -m pre cattaneo: {err}", file=sys.stderr)
        return 2
    print(f"wrote {case} and {case.with_name(case.stem + '-geometry.h5')}")
    print(f"expected half-width a = {scene.half_width:.6g}, arc elements h = {scene.h:.4g} over |x| <= 1.5 a")
    return 0


def _cmd_hertz(args: argparse.Namespace) -> int:
    from .hertz import Cylinder, HertzCaseError, write_hertz_case

    cyl = Cylinder(radius=args.radius, youngs_modulus=args.youngs_modulus,
                   poisson_ratio=args.poisson_ratio, indentation=args.indentation)
    penalty = args.penalty_normal
    if penalty is not None and penalty != "auto":
        try:
            penalty = float(penalty)
        except ValueError:
            penalty = args.penalty_normal  # cylinder_case names it
    try:
        geometry, case, fresh = write_hertz_case(
            cyl, args.mesh, args.layout, args.out, force=args.force, n_steps=args.steps,
            method=args.method, penalty_normal=penalty, edge_refine=args.edge_refine,
            surface_size=args.surface_size)
    except (HertzCaseError, OSError) as err:
        print(f"python -m pre hertz: {err}", file=sys.stderr)
        return 2
    print(f"wrote {geometry}" if fresh else f"kept {geometry} (the same cylinder)")
    print(f"wrote {case}")
    print(f"expected half-width a = {cyl.half_width:.6g} (a/R = {cyl.half_width / cyl.radius:.4g}; "
          f"estimate, docs/howto.md)")
    return 0


def _write_scene3d(command: str, write: Callable[[], Any], dofs: Callable[[str, str], dict[str, int]],
                   same: str, closing: str) -> int:
    """Run a 3D scene's writer ``write()`` (``(geometry, cases, geometry written)``); a
    refusal is one line on stderr naming ``python -m pre COMMAND`` and exit code 2. Print
    what was written, each case's DOFs (``dofs(mesh, layout)``: body -> DOFs) and ``closing``."""
    from .files import OutputError
    from .hertz import HertzCaseError
    try:
        geometry, cases, fresh = write()
    except (HertzCaseError, OutputError, OSError) as err:
        print(f"python -m pre {command}: {err}", file=sys.stderr)
        return 2
    print(f"wrote {geometry}" if fresh else f"kept {geometry} (the same {same})")
    for case in cases:
        mesh, layout = case.stem.split("-", 1)
        each = dofs(mesh, layout)
        parts = f" ({', '.join(f'{name} {n}' for name, n in each.items())})" if len(each) > 1 else ""
        print(f"wrote {case}: {sum(each.values())} DOFs{parts}")
    print(closing)
    return 0


def _cmd_hertz3d(args: argparse.Namespace) -> int:
    from .hertz3d import Ball, body_dofs, write_hertz3d

    ball = Ball(radius=args.radius, youngs_modulus=args.youngs_modulus,
                poisson_ratio=args.poisson_ratio, indentation=args.indentation, material=args.material,
                master=args.master, block_size=args.block_size, block_cell=args.block_cell,
                block_youngs_modulus=args.block_youngs_modulus, block_poisson_ratio=args.block_poisson_ratio,
                grid=args.grid)
    meshes = args.mesh or ["p3" if args.grid == "polar" else "m2"]
    return _write_scene3d(
        "hertz3d", lambda: write_hertz3d(ball, meshes, args.layout, args.out, force=args.force,
                                         n_steps=args.steps, method=args.method,
                                         penalty_normal=args.penalty_normal),
        lambda mesh, layout: body_dofs(ball, mesh, layout),
        "ball" if ball.master == "rigid" else "ball and block",
        f"expected contact radius a = sqrt(R d) = {ball.half_width:.6g} "
        f"(a/R = {ball.half_width / ball.radius:.4g}; Hertz for the approach d, an estimate)")


def _cmd_ironing3d(args: argparse.Namespace) -> int:
    from .ironing3d import Iron, case_dofs, write_ironing3d

    iron = Iron(friction=args.friction)
    return _write_scene3d(
        "ironing3d", lambda: write_ironing3d(iron, args.mesh, args.layout, args.out, force=args.force,
                                             steps=args.steps, n_gauss=args.n_gauss or None,
                                             penalty_normal=args.penalty_normal, method=args.method),
        lambda mesh, layout: {"slab": case_dofs(iron, mesh, layout)["total"]}, "die",
        f"expected contact radius sqrt(R d) = {iron.contact_radius:.4g}")


def _cmd_cattaneo3d(args: argparse.Namespace) -> int:
    from .cattaneo3d import HalfBall, case_dofs, write_cattaneo3d

    ball = HalfBall(youngs_modulus=args.youngs_modulus, poisson_ratio=args.poisson_ratio,
                    indentation=args.indentation, friction=args.friction, target=args.target,
                    shear=args.shear, press_steps=args.steps[0], shear_steps=args.steps[1], method=args.method,
                    grid=args.grid)
    meshes = args.mesh or ["p1" if args.grid == "polar" else "m1"]
    return _write_scene3d(
        "cattaneo3d", lambda: write_cattaneo3d(ball, meshes, args.layout, args.out, force=args.force),
        lambda mesh, layout: case_dofs(ball, mesh, layout), "half ball",
        f"expected contact radius sqrt(R d) = {ball.half_width:.4g}; the plane moves {ball.plane_shear:.4g} "
        f"along x in the shear phase")


def _cmd_refine(args: argparse.Namespace) -> int:
    if not args.input.endswith(".nml"):
        return _refine_zone(args)
    from .refine import discretize_case, write_dump

    if args.output is None:
        print("python -m pre refine: a case (.nml) needs -o DUMP.h5 (the discretization dump); "
              "a result file (.h5) is refined at its contact zone", file=sys.stderr)
        return 2
    disc = discretize_case(args.input)
    write_dump(args.output, disc)
    for name, b in disc.bodies.items():
        layer = f", layer degree {b.layer.degree} x {len(b.layer.weights)}" if b.layer else ""
        print(f"{name}: bulk degree {b.bulk.degree} {b.bulk.shape[1]} x {b.bulk.shape[0]}{layer}; "
              f"DOF interface {b.interface_dofs} bulk {b.bulk_dofs} total {b.total_dofs}")
    return 0


def _refine_zone(args: argparse.Namespace) -> int:
    """``pre refine RESULT.h5``: the case refined at the contact zone's edges (the
    measurements and the case are the result's: post.adapt)."""
    from post.adapt import AdaptError, accepted, parse_target, refine_result
    from post.reader import BadResultError

    from .files import OutputError

    try:
        target = parse_target(args.target)
        done = refine_result(args.input, target, args.out, force=args.force)
    except (AdaptError, BadResultError, OutputError, FileNotFoundError, ValueError) as err:
        print(f"python -m pre refine: {err}", file=sys.stderr)
        return 2
    print(f"{args.input}: largest estimated edge error {done.estimate:.2%} (target {target:.2%}: "
          f"edges above {accepted(target):.2%} refined)")
    for name, (n_along, n_across) in done.bodies.items():
        print(f"  {name}: {n_along} elements along the contact edge, {n_across} rows across")
    if not done.bodies:
        print("  every edge is within the accepted estimate: the case is written unchanged")
    print(f"wrote {done.case} ({done.n_dofs} DOFs; from {done.source})")
    return 0


def _cmd_plot_layout(args: argparse.Namespace) -> int:
    from .plot import plot_layout

    print(plot_layout(args.case, args.body, args.output))
    return 0


def _cmd_figures(args: argparse.Namespace) -> int:
    from .plot import write_figures

    for path in write_figures(args.out):
        print(path)
    return 0


def build_parser() -> argparse.ArgumentParser:
    """The argparse parser with one subparser per subcommand."""
    p = argparse.ArgumentParser(prog="python -m pre", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="command", required=True)

    s = sub.add_parser("geometry", help="geometry spec (TOML) -> geometry file and case file")
    s.add_argument("spec", help="spec file (.toml; docs/pre.md)")
    s.add_argument("--out", default=None, help="output folder (default: the spec's folder)")
    s.add_argument("--force", action="store_true",
                   help="write the geometry and case files although they exist and differ from the spec "
                        "(what is replaced is listed)")
    s.set_defaults(func=_cmd_geometry)

    s = sub.add_parser("geometry3d", help="spec of 3D bodies (TOML) -> geometry file of volumes and case file")
    s.add_argument("spec", help="spec file (.toml; docs/pre.md, '3D bodies')")
    s.add_argument("--out", default=None, help="output folder (default: the spec's folder)")
    s.add_argument("--force", action="store_true",
                   help="write the geometry and case files although they exist and differ from the spec "
                        "(what is replaced is listed)")
    s.set_defaults(func=_cmd_geometry3d)

    s = sub.add_parser("cases", help="write geometry files and case namelists")
    s.add_argument("--out", default="cases",
                   help="output folder (default: cases, relative to the current directory: run "
                        "it from the repository root to refresh the committed cases)")
    s.set_defaults(func=_cmd_cases)

    s = sub.add_parser("hertz", help="a Hertz case (cylinder on a rigid flat) for any cylinder")
    s.add_argument("--radius", type=float, default=1.0, help="cylinder radius R (default 1)")
    s.add_argument("--youngs-modulus", type=float, default=1.0, help="E (default 1)")
    s.add_argument("--poisson-ratio", type=float, default=0.3, help="nu in (-1, 0.5) (default 0.3)")
    s.add_argument("--indentation", type=float, default=0.01,
                   help="downward displacement d of the cylinder's centre cut, 0 < d < R/10 "
                        "(default 0.01)")
    s.add_argument("--mesh", default="m3", help="mesh level m1 .. m6 as the committed hertz "
                                                "cases (default m3)")
    s.add_argument("--layout", default="NN2.2", help="layout, e.g. N2, NN2.2 (default NN2.2)")
    s.add_argument("--steps", type=int, default=None, help="load steps (default: the committed 5)")
    s.add_argument("--method", default=None,
                   help="&contact method, e.g. gpts, mortar, alm (default: the committed case's)")
    s.add_argument("--penalty-normal", default=None,
                   help="a number, or 'auto' (voiga chooses); default: the committed case's "
                        "scaled by E and 1/a (its compliance relative to a)")
    s.add_argument("--edge-refine", type=int, default=1, metavar="K",
                   help="split the arc elements around the expected edge of the zone (0.9 a "
                        "to 1.1 a) and the first coarse one beyond the graded zone into K "
                        "(default 1; the case is <mesh>-<layout>-edgeK.nml)")
    s.add_argument("--surface-size", type=float, default=None, metavar="S",
                   help="radial size of the element at the surface, a fraction of the "
                        "expected half-width a (default: as the committed scene, about 1/15)")
    s.add_argument("--out", required=True, help="folder for geometry.h5 and <mesh>-<layout>.nml")
    s.add_argument("--force", action="store_true", help="overwrite existing files")
    s.set_defaults(func=_cmd_hertz)

    s = sub.add_parser("hertz3d", help="the 3D Hertz scene: a quarter hemisphere (ball octant) "
                                       "pressed on a rigid plane or an elastic block; geometry.h5 and a case per mesh "
                                       "and layout")
    s.add_argument("out", help="folder for geometry.h5 and <mesh>-<layout>.nml (not cases/: voiga "
                               "cannot run 3D contact yet)")
    s.add_argument("--mesh", nargs="+", default=None,
                   help="meshes: m1 .. m4 on the Cartesian grid (default m2), p1 .. p4 on the polar one "
                        "(default p3)")
    s.add_argument("--layout", nargs="+", default=["NN2.2"],
                   help="solid layouts, e.g. N2 N3 NN2.1 NN2.2 (default NN2.2)")
    s.add_argument("--grid", default="cartesian", choices=("cartesian", "polar"),
                   help="the ball's parametrization: cartesian (about a horizontal axis; the contact "
                        "at a regular corner) or polar (about the vertical axis through the contact: "
                        "knot lines along the zone's edge, which it splits; default cartesian)")
    s.add_argument("--radius", type=float, default=1.0, help="ball radius R (default 1)")
    s.add_argument("--youngs-modulus", type=float, default=1.0, help="E (default 1)")
    s.add_argument("--poisson-ratio", type=float, default=0.3, help="nu in (-1, 0.5) (default 0.3)")
    s.add_argument("--indentation", type=float, default=0.01,
                   help="downward displacement d of the top face, 0 < d < R/10 (default 0.01)")
    s.add_argument("--material", default="linear", choices=("linear", "neo-hookean"),
                   help="material law (default linear)")
    s.add_argument("--steps", type=int, default=None, help="load steps (default 5)")
    s.add_argument("--method", default="mortar", help="&contact method (default mortar, voiga's on solids)")
    s.add_argument("--penalty-normal", type=float, default=None,
                   help="&contact penalty_normal (default: none written, voiga's automatic one)")
    s.add_argument("--master", default="rigid", choices=("rigid", "block"),
                   help="rigid: the rigid plane z = -R (default); block: an elastic block "
                        "[0, L] x [0, L] x [-R - H, -R] under the ball, its bottom fixed")
    s.add_argument("--block-size", type=float, default=1.0,
                   help="--master block: L = H over R (default 1, ten contact radii)")
    s.add_argument("--block-cell", type=float, default=1.3,
                   help="--master block: its top cells over the ball's fine ones (default 1.3: "
                        "comparable, not matching)")
    s.add_argument("--block-youngs-modulus", type=float, default=None,
                   help="--master block: the block's E (default: the ball's)")
    s.add_argument("--block-poisson-ratio", type=float, default=None,
                   help="--master block: the block's nu (default: the ball's)")
    s.add_argument("--force", action="store_true", help="overwrite existing files")
    s.set_defaults(func=_cmd_hertz3d)

    s = sub.add_parser("ironing3d", help="the 3D ironing scene: a rigid sphere pressed into a Neo-Hookean "
                                         "slab and slid along it (docs/ironing3d.md)")
    s.add_argument("out", help="folder for geometry.h5 and <mesh>-<layout>.nml")
    s.add_argument("--mesh", nargs="+", default=["m1"], help="mesh levels m1 .. m3 (default m1)")
    s.add_argument("--layout", nargs="+", default=["N2"], help="solid layouts, e.g. N2 NN2.1 NN2.2 (default N2)")
    s.add_argument("--friction", type=float, default=0.3, help="Coulomb's mu (default 0.3)")
    s.add_argument("--steps", type=int, nargs=2, default=None, metavar=("PRESS", "SLIDE"),
                   help="steps of the press and slide phases (default 10 40)")
    s.add_argument("--n-gauss", type=int, default=0,
                   help="&contact n_gauss per direction (default 0: none written, voiga's layer degree + 1)")
    s.add_argument("--penalty-normal", type=float, default=None,
                   help="&contact penalty_normal (default: none written, voiga's automatic one)")
    s.add_argument("--method", default="gpts", choices=("gpts", "mortar"),
                   help="&contact method (default gpts, the scene's reference)")
    s.add_argument("--force", action="store_true", help="overwrite existing files")
    s.set_defaults(func=_cmd_ironing3d)

    s = sub.add_parser("cattaneo3d", help="the 3D Cattaneo-Mindlin scene: a half ball pressed on a rigid "
                                          "plane without friction, then sheared with it (docs/cattaneo3d.md)")
    s.add_argument("out", help="folder for geometry.h5 and <mesh>-<layout>.nml")
    s.add_argument("--mesh", nargs="+", default=None,
                   help="meshes: m1 .. m4 on the Cartesian grid (default m1), p1 .. p4 on the polar one "
                        "(default p1)")
    s.add_argument("--layout", nargs="+", default=["N2"], help="solid layouts, e.g. N2 NN2.2 (default N2)")
    s.add_argument("--grid", default="cartesian", choices=("cartesian", "polar"),
                   help="cartesian: the half shell (default); polar: the half ball about the vertical axis "
                        "through the contact, knot lines along the contact's and the stick zone's edges")
    s.add_argument("--youngs-modulus", type=float, default=1.0, help="E (default 1)")
    s.add_argument("--poisson-ratio", type=float, default=0.3, help="nu in (-1, 0.5) (default 0.3)")
    s.add_argument("--indentation", type=float, default=0.01, help="the press d, 0 < d < R/10 (default 0.01)")
    s.add_argument("--friction", type=float, default=0.3, help="Coulomb's mu in the shear (default 0.3)")
    s.add_argument("--target", type=float, default=0.5,
                   help="Q/(mu P) the shear aims at, in (0, 1) (default 0.5)")
    s.add_argument("--shear", type=float, default=None,
                   help="the plane's move along x (default: the estimate for --target)")
    s.add_argument("--steps", type=int, nargs=2, default=(10, 10), metavar=("PRESS", "SHEAR"),
                   help="steps of the press and shear phases (default 10 10)")
    s.add_argument("--method", default=None, help="&contact method (default: none written, voiga's)")
    s.add_argument("--force", action="store_true", help="overwrite existing files")
    s.set_defaults(func=_cmd_cattaneo3d)

    s = sub.add_parser("cattaneo", help="a Cattaneo-Mindlin case: a half cylinder pressed onto a "
                                        "rigid flat, its mirror image or a block, then sheared")
    s.add_argument("--master", default="rigid", choices=("rigid", "mirror", "block"),
                   help="rigid: the rigid line y = -R (default); mirror: the cylinder's mirror image "
                        "(elastically similar, symmetric); block: a block of the same material")
    s.add_argument("--radius", type=float, default=1.0, help="cylinder radius R (default 1)")
    s.add_argument("--youngs-modulus", type=float, default=1.0, help="E (default 1)")
    s.add_argument("--poisson-ratio", type=float, default=0.49, help="nu (default 0.49)")
    s.add_argument("--indentation", type=float, default=0.01, help="press depth d (default 0.01)")
    s.add_argument("--friction", type=float, default=0.3, help="mu of the shear (default 0.3)")
    s.add_argument("--press-friction", type=float, default=None,
                   help="mu of the press (default: --friction; 0: a frictionless press)")
    s.add_argument("--elements-per-a", type=float, default=20.0,
                   help="arc elements per expected half-width a over |x| <= 1.5 a (default 20)")
    s.add_argument("--layout", default="NN2.2", help="layout of both bodies (default NN2.2)")
    s.add_argument("--method", default=None, help="&contact method (default: voiga's)")
    s.add_argument("--penalty-normal", type=float, default=None, help="default: automatic")
    s.add_argument("--shear", type=float, default=3.5e-3,
                   help="tangential displacement of the master in the shear phase (default 3.5e-3: "
                        "Q/(mu P) about 0.55 for the defaults)")
    s.add_argument("--steps", type=int, nargs=2, default=[20, 20], metavar=("PRESS", "SHEAR"),
                   help="load steps of the press and of the shear (default 20 20)")
    s.add_argument("--out", required=True, help="folder for <master>-<layout>-a<n>.nml and its geometry")
    s.add_argument("--force", action="store_true", help="overwrite existing files")
    s.set_defaults(func=_cmd_cattaneo)

    s = sub.add_parser("refine", help="a result: its case refined at the contact zone's edges; "
                                      "a case (.nml): refine with splipy, write the discretization dump")
    s.add_argument("input", help="result file (.h5) to refine the contact zone of, or case namelist (.nml)")
    s.add_argument("-o", "--output", default=None, help="dump file (.h5), for a case")
    s.add_argument("--target", default="0.2%",
                   help="estimated edge error to refine to, e.g. 0.2%% (default; docs/contact-accuracy.md)")
    s.add_argument("--out", default=None,
                   help="folder of the refined case (default: <case>-zone<k> beside the result)")
    s.add_argument("--force", action="store_true", help="overwrite an existing refined case")
    s.set_defaults(func=_cmd_refine)

    s = sub.add_parser("plot-layout", help="control nets and contact basis of one body (PNG)")
    s.add_argument("case", help="case namelist (.nml)")
    s.add_argument("--body", required=True, help="body name")
    s.add_argument("-o", "--output", required=True, help="PNG file")
    s.set_defaults(func=_cmd_plot_layout)

    s = sub.add_parser("figures", help="write the docs figures")
    s.add_argument("--out", default=str(Path("docs") / "figures"),
                   help="output folder (default: docs/figures, relative to the current directory)")
    s.set_defaults(func=_cmd_figures)
    return p


def main(argv: list[str] | None = None) -> int:
    """Entry point."""
    args = build_parser().parse_args(argv)
    return int(args.func(args))


if __name__ == "__main__":
    sys.exit(main())
