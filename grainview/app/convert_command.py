"""``grainview convert``: another code's output turned into a file of the contract, one
subcommand per reader of :mod:`grainview.formats` (docs/formats.md)."""

from __future__ import annotations

from ..contract.errors import GrainviewError
from .settings import no_compress_option

HELP = "turn another code's output into a file of the contract"
"""The command's line in ``grainview --help``."""


def _convert_peer(args) -> int:
    from ..formats.peers import convert_peer

    count = convert_peer(args.out, args.raw, args.sample, engine=args.format, overwrite=args.overwrite,
                         compress=not args.no_compress)
    print(f"wrote {args.out}: {count} snapshots from {args.format} (check it: grainview info {args.out} --check)")
    return 0


def _convert(args) -> int:
    from ..formats.lammps import convert_lammps

    columns = None
    if args.columns:
        try:
            columns = dict(item.split("=", 1) for item in args.columns.split(","))
        except ValueError:
            raise GrainviewError(f"--columns {args.columns}: expected QUANTITY=COLUMN,... (e.g. "
                                 "patom1=c_pairs[1],patom2=c_pairs[2])") from None
    count = convert_lammps(args.out, args.particles, args.contacts, args.walls, log=args.log,
                           time_step=args.time_step, columns=columns, inertia=args.inertia,
                           overwrite=args.overwrite, compress=not args.no_compress,
                           progress=args.progress != "off")
    print(f"wrote {args.out}: {count} snapshots from LAMMPS (check it: grainview info {args.out} --check)")
    return 0


def _convert_lmgc90(args) -> int:
    from ..formats.lmgc90 import convert_lmgc90

    count = convert_lmgc90(args.out, args.run, x_period=args.x_period, overwrite=args.overwrite,
                           compress=not args.no_compress, progress=args.progress != "off")
    print(f"wrote {args.out}: {count} snapshots from LMGC90 (check it: grainview info {args.out} --check)")
    return 0


def _mercurydpm_units(text):
    """``--units si`` or ``--units length=L,mass=M,time=T`` as the reader's ``units``."""
    if text.strip().lower() == "si":
        return "si"
    try:
        return {key.strip(): float(value) for key, value in (item.split("=", 1) for item in text.split(","))}
    except ValueError:
        raise GrainviewError(f"--units {text}: expected si or length=L,mass=M,time=T (the SI value of one unit of "
                             "the run: m, kg, s)") from None


def _convert_mercurydpm(args) -> int:
    import warnings

    from ..formats.mercurydpm import convert_mercurydpm

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        count = convert_mercurydpm(args.out, args.data, args.fstat, args.restart,
                                   units=_mercurydpm_units(args.units), overwrite=args.overwrite,
                                   compress=not args.no_compress, progress=args.progress != "off")
    for note in caught:
        print(f"note: {note.message}")
    print(f"wrote {args.out}: {count} snapshots from MercuryDPM (check it: grainview info {args.out} --check)")
    return 0


def _convert_pegs(args) -> int:
    import warnings

    from ..formats.pegs import convert_pegs

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        count = convert_pegs(args.out, args.adjacency, args.positions, metres_per_pixel=args.metres_per_pixel,
                             force_unit_n=args.force_unit_n, frame_interval_s=args.frame_interval,
                             thickness_m=args.thickness, density_kg_m3=args.density, overwrite=args.overwrite,
                             compress=not args.no_compress, progress=args.progress != "off")
    for note in caught:
        print(f"note: {note.message}")
    print(f"wrote {args.out}: {count} frames from PeGS2 (check it: grainview info {args.out} --check)")
    return 0


def convert_parser(sub):
    """``grainview convert FORMAT``: one subcommand per reader."""
    convert = sub.add_parser("convert", help=HELP,
                             description="Read another code's output and write a validated, compressed file of "
                             "the grainview contract (docs/formats.md); an existing file is kept unless "
                             "--overwrite.")
    formats = convert.add_subparsers(dest="format", metavar="FORMAT", required=True)
    lammps = formats.add_parser("lammps", help="a LAMMPS 2D granular run (dump custom + dump local)",
                                description="A LAMMPS 2D granular run: the particles' dump custom (id radius mass "
                                "x y, optionally vx vy omegaz), the pairs' dump local (compute property/local "
                                "patom1 patom2; compute pair/local fx fy fz p1 p2 p3), optionally the walls' dump "
                                "custom of fix wall/gran ... contacts arrays, and the log (time step and the "
                                "computes' definitions). Contacts: touching pairs with a compressive normal force "
                                "(docs/formats.md).")
    lammps.add_argument("--particles", required=True, help="the particles' dump custom")
    lammps.add_argument("--contacts", required=True, help="the pairs' dump local")
    lammps.add_argument("--walls", help="the walls' dump custom (id and f_ID[1..8] of fix wall/gran ... contacts; "
                        "default: none, no wall contacts)")
    lammps.add_argument("--log", help="the run's log.lammps or input script: time step and compute definitions "
                        "(default: none; then --time-step is needed)")
    lammps.add_argument("--time-step", type=float, help="the time step in s (default: the log's)")
    lammps.add_argument("--columns", help="which dump local column holds each quantity, e.g. "
                        "patom1=c_pairs[1],patom2=c_pairs[2],fx=c_forces[2],fy=c_forces[3],p1=c_forces[5],"
                        "p2=c_forces[6] (default: from the log or the columns' own names)")
    lammps.add_argument("--inertia", choices=("auto", "disc", "sphere"), default="auto",
                        help="moments of inertia m r^2/2 (disc) or 2 m r^2/5 (sphere); auto: as the log's "
                        "fix nve/sphere says, disc without a log (default: auto)")
    lammps.add_argument("--out", required=True, help="the netCDF file to write")
    lammps.add_argument("--overwrite", action="store_true", help="replace an existing --out")
    lammps.add_argument("--progress", choices=("on", "off"), default="on", help="progress bar (default: on)")
    no_compress_option(lammps)
    lammps.set_defaults(func=_convert)
    lmgc90 = formats.add_parser("lmgc90", help="an LMGC90 2D rigid run (DATBOX + OUTBOX text files)",
                                description="An LMGC90 2D rigid run: its folder holding DATBOX/BODIES.DAT and "
                                "BULK_BEHAV.DAT (RBDY2 bodies with one DISKx, convex POLYG or JONCx contactor) and "
                                "OUTBOX/DOF.OUT.n with Vloc_Rloc.OUT.n (DKDKx, DKJCx, PLPLx, PLJCx, DKPLx). "
                                "Contacts: body pairs with a compressive normal force; two points on a pair make a "
                                "double contact (docs/formats.md).")
    lmgc90.add_argument("run", help="the run folder (holding DATBOX/ and OUTBOX/)")
    lmgc90.add_argument("--x-period", type=float, default=None, metavar="L",
                        help="the run's period along x in m, as its script gave chipy.SetPeriodicCondition(xperiod=L) "
                             "(no output file records it; default: a run bounded by walls)")
    lmgc90.add_argument("--out", required=True, help="the netCDF file to write")
    lmgc90.add_argument("--overwrite", action="store_true", help="replace an existing --out")
    lmgc90.add_argument("--progress", choices=("on", "off"), default="on", help="progress bar (default: on)")
    no_compress_option(lmgc90)
    lmgc90.set_defaults(func=_convert_lmgc90)
    mercury = formats.add_parser("mercurydpm", help="a MercuryDPM 2D run (.data + .fstat + .restart)",
                                 description="A MercuryDPM 2D run: its .data (particles), .fstat (contacts, each "
                                 "pair written from both sides) and .restart (dimensions, masses, walls). MercuryDPM "
                                 "has no units of its own: say which (--units). Contacts: overlapping pairs with a "
                                 "compressive normal force, one per pair (docs/formats.md).")
    mercury.add_argument("data", help="the run's .data file")
    mercury.add_argument("--fstat", help="the run's .fstat file (default: beside the .data, same name)")
    mercury.add_argument("--restart", help="the run's .restart file (default: beside the .data, same name)")
    mercury.add_argument("--units", required=True, help="si (the run is in m, kg, s), or length=L,mass=M,time=T: the "
                         "SI value of one length, mass and time unit of the run (m, kg, s)")
    mercury.add_argument("--out", required=True, help="the netCDF file to write")
    mercury.add_argument("--overwrite", action="store_true", help="replace an existing --out")
    mercury.add_argument("--progress", choices=("on", "off"), default="on", help="progress bar (default: on)")
    no_compress_option(mercury)
    mercury.set_defaults(func=_convert_mercurydpm)
    pegs = formats.add_parser("pegs", help="a photoelastic experiment solved by PeGS2 (adjacency list + positions)",
                              description="A photoelastic experiment solved by PeGS2: its adjacency lists (rows "
                              "frame, id1, id2, tangential force, normal force; id2 -1 a wall) and the disks "
                              "(particle_positions.txt of particleTrack, or the *_centers.txt of particleDetect), in "
                              "pixels. The scale and the force unit are required (docs/formats.md).")
    import inspect

    from ..formats.pegs import convert_pegs

    pegs.add_argument("adjacency", nargs="+", help="Adjacency_list.txt, or the frames' *_Adjacency.txt")
    pegs.add_argument("--positions", nargs="+", required=True,
                      help="particle_positions.txt, or the frames' *_centers.txt")
    pegs.add_argument("--metres-per-pixel", type=float, required=True, help="the image scale, m per pixel "
                      "(PeGS2's metersperpixel)")
    pegs.add_argument("--force-unit-n", type=float, required=True, help="newtons per force unit of the adjacency "
                      "list (1 when PeGS2's fsigma is calibrated in N)")
    for flag, parameter, text in (("--frame-interval", "frame_interval_s", "time between frames, s (default: {:g})"),
                                  ("--thickness", "thickness_m", "the disks' thickness, m (default: {:g}; stresses "
                                   "are per this thickness)"),
                                  ("--density", "density_kg_m3", "the disks' density for their masses, kg/m^3 (not "
                                   "measured; default: {:g})")):
        default = inspect.signature(convert_pegs).parameters[parameter].default
        pegs.add_argument(flag, type=float, default=default, help=text.format(default))
    pegs.add_argument("--out", required=True, help="the netCDF file to write")
    pegs.add_argument("--overwrite", action="store_true", help="replace an existing --out")
    pegs.add_argument("--progress", choices=("on", "off"), default="on", help="progress bar (default: on)")
    no_compress_option(pegs)
    pegs.set_defaults(func=_convert_pegs)
    for engine, version in (("box2d", "Box2D 2.3"), ("pymunk", "pymunk")):
        peer = formats.add_parser(engine, help=f"a {version} run of the cross-check (raw snapshots)",
                                  description=f"A {version} run of the cross-check harness (benchmarks/crosscheck/): "
                                  "the engine's folder of raw snapshots (snap_*.npz, meta.json) and the sample it "
                                  "started from (docs/formats.md).")
        peer.add_argument("raw", help="the engine's folder of raw snapshots")
        peer.add_argument("--sample", required=True, help="the cross-check sample's .npz the engine started from")
        peer.add_argument("--out", required=True, help="the netCDF file to write")
        peer.add_argument("--overwrite", action="store_true", help="replace an existing --out")
        no_compress_option(peer)
        peer.set_defaults(func=_convert_peer)
