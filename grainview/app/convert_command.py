"""``grainview convert``: another code's output turned into a file of the contract, one
subcommand per reader of the readers' registry (:mod:`grainview.formats.readers`,
docs/formats.md): each reader's record gives its subcommand's help, description and own
arguments, and the conversion it calls; the options every reader has are added here."""

from __future__ import annotations

import inspect

from .settings import no_compress_option

HELP = "turn another code's output into a file of the contract"
"""The command's line in ``grainview --help``."""


def _run(args) -> int:
    """Convert as the record of ``args.format`` says, then say what was written."""
    import warnings

    from ..formats.readers import load, reader

    convert = reader(args.format).convert
    options = {}
    for argument in convert.arguments:
        value = getattr(args, argument.dest)
        if argument.parse and value is not None:
            value = load(argument.parse)(value)
        options[argument.keyword or argument.dest] = value
    if convert.progress:
        options["progress"] = args.progress != "off"
    function = load(convert.function)
    if convert.notes:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            count = function(args.out, **options, **convert.fixed, overwrite=args.overwrite,
                             compress=not args.no_compress)
        for note in caught:
            print(f"note: {note.message}")
    else:
        count = function(args.out, **options, **convert.fixed, overwrite=args.overwrite, compress=not args.no_compress)
    print(f"wrote {args.out}: {count} {convert.written} (check it: grainview info {args.out} --check)")
    return 0


def _add_argument(parser, argument):
    """One of a reader's own arguments, its default read from its function where it says so."""
    from ..formats.readers import load

    settings = dict(argument.settings)
    if argument.default_from:
        default = inspect.signature(load(argument.default_from)).parameters[argument.keyword].default
        settings.update(default=default, help=settings["help"].format(default))
    parser.add_argument(*argument.flags, **settings)


def convert_parser(sub):
    """``grainview convert FORMAT``: one subcommand per reader of the registry."""
    from ..formats.readers import readers

    convert = sub.add_parser("convert", help=HELP,
                             description="Read another code's output and write a validated, compressed file of "
                             "the grainview contract (docs/formats.md); an existing file is kept unless "
                             "--overwrite.")
    formats = convert.add_subparsers(dest="format", metavar="FORMAT", required=True)
    for name, reader in readers().items():
        command = reader.convert
        parser = formats.add_parser(name, help=command.help, description=command.description)
        for argument in command.arguments:
            _add_argument(parser, argument)
        parser.add_argument("--out", required=True, help="the netCDF file to write")
        parser.add_argument("--overwrite", action="store_true", help="replace an existing --out")
        if command.progress:
            parser.add_argument("--progress", choices=("on", "off"), default="on", help="progress bar (default: on)")
        no_compress_option(parser)
        parser.set_defaults(func=_run)
