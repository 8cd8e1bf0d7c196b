"""`python3 -m bumpbake.dask bake ... --scheduler ADDRESS`: `bumpbake bake`
on a Dask cluster, for users who never write Python; `bumpbake bake
--scheduler ADDRESS` runs it with the same arguments.

The arguments are bumpbake bake's, read the way its C parser reads them
(getopt_long: long options, unambiguous prefixes of them, --name=value,
short -o and -q, options and HEIGHTs in any order), plus --scheduler. A
batch (--out-dir) is bumpbake.dask.bake_files; a single bake (-o, --normal
FILE, ...) is bumpbake.dask.bake_big, its trace split over the workers.
The files record the command as the CLI would have recorded it without
--scheduler, so they are the bytes the same command writes on one machine.
It prints what the CLI prints (wrote/up to date lines, the batch's
summary, --json lines) and exits as it does: 0, 1 when an input failed, 2
for a usage error.
"""

import json
import os
import sys

from .. import OUTPUTS, ArgumentError, Error

USAGE = """usage: python3 -m bumpbake.dask bake HEIGHT... --scale S --scheduler ADDRESS [OPTIONS]
                 (-o PREFIX | --normal FILE | ... | --out-dir DIR)

bumpbake bake on a Dask cluster (see bumpbake bake --help for its options):
  --scheduler ADDRESS   the Dask scheduler, e.g. tcp://host:8786 (dask-scheduler
                        prints it); the workers must see the files at the same
                        paths (shared storage)
With --out-dir, a batch: its inputs are baked on the workers, in chunks.
Else one map: its trace is split over the workers (bit for bit a single
machine's bake). docs/cluster.md says how to start a cluster.
"""

# bumpbake bake's options: name -> (takes a value, what it sets).
_VALUED = ("scale", "rays", "slices", "filter-radius", "filter-threshold", "bias", "power",
           "basis", "normal-filter", "normal-y", "threads", "channel", "depth", "normal",
           "weights", "ssbump", "ao", "bent", "filtered", "slope", "lit", "output", "out-dir",
           "maps", "name", "depfile", "texture-format", "vtf-version", "vtf-flags", "vmt",
           "materials", "basetexture", "scheduler")
_FLAGS = ("clamp", "mips", "keep-going", "force", "json", "quiet", "nomip", "fast-compression",
          "help")
# bumpbake bake's options that the Python package does not take yet.
_NOT_ON_A_CLUSTER = ("bounce", "bounces", "bounce-albedo", "brightness")
_SHORT = {"o": "output", "q": "quiet", "h": "help"}


class Usage(Exception):
    """A usage error: printed as `bumpbake bake: MESSAGE`, exit 2."""


def _long(name):
    """The option an unambiguous prefix names, as getopt_long finds it."""
    every = _VALUED + _FLAGS + _NOT_ON_A_CLUSTER
    if name in every:
        return name
    found = [o for o in every if o.startswith(name)]
    if len(found) == 1:
        return found[0]
    if not found:
        raise Usage(f"unknown option '--{name}'")
    raise Usage(f"option '--{name}' is ambiguous ({', '.join('--' + f for f in found)})")


def parse(args):
    """(options [(name, value or None, the words typed)], positionals,
    the indices of args that --scheduler took)."""
    options, positionals, scheduler = [], [], set()
    i = 0
    while i < len(args):
        word = args[i]
        first = i
        i += 1
        if word == "--":
            positionals += args[i:]
            break
        if word.startswith("--"):
            name, eq, value = word[2:].partition("=")
            name = _long(name)
            if name in _NOT_ON_A_CLUSTER:
                raise Usage(f"--{name} is not available with --scheduler yet: bake on one "
                            "machine for inter-reflection and brightness maps")
            typed = [word]
            if name in _VALUED:
                if not eq:
                    if i >= len(args):
                        raise Usage(f"option '--{name}' needs a value")
                    value = args[i]
                    typed.append(value)
                    i += 1
            elif eq:
                raise Usage(f"option '--{name}' takes no value")
            else:
                value = None
            options.append((name, value, typed))
            if name == "scheduler":
                scheduler.update(range(first, i))
        elif word.startswith("-") and word != "-":
            typed = [word]
            k = 1
            while k < len(word):
                letter = word[k]
                if letter not in _SHORT:
                    raise Usage(f"unknown option '-{letter}'")
                name = _SHORT[letter]
                k += 1
                if name in _VALUED:
                    value = word[k:]
                    if not value:
                        if i >= len(args):
                            raise Usage(f"option '-{letter}' needs a value")
                        value = args[i]
                        typed.append(value)
                        i += 1
                    options.append((name, value, typed))
                    typed = []
                    break
                options.append((name, None, typed))
                typed = []
        else:
            positionals.append(word)
    return options, positionals, scheduler


def _number(name, value, kind):
    try:
        return kind(value)
    except ValueError:
        raise Usage(f"--{name}: '{value}' is not a{'n integer' if kind is int else ' number'}")


def _command_words(options, drop=("scheduler",)):
    return [w for name, _, typed in options if name not in drop for w in typed]


def _bake_arguments(options):
    """Keyword arguments of bumpbake.dask's bake functions from the options."""
    kw, outputs = {}, {}
    numbers = {"scale": float, "rays": int, "slices": int, "filter-radius": int,
               "filter-threshold": float, "bias": float, "power": float, "threads": int}
    for name, value, _ in options:
        key = name.replace("-", "_")
        if name in numbers:
            kw[key] = _number(name, value, numbers[name])
        elif name in ("basis", "normal-filter", "normal-y", "channel", "prefix", "name",
                      "depfile", "slope"):
            kw[key] = value
        elif name == "depth":
            kw["depth"] = value
        elif name == "clamp":
            kw["clamp"] = True
        elif name == "mips":
            kw["mips"] = True
        elif name in OUTPUTS:
            outputs[name] = value
        elif name == "output":
            kw["prefix"] = value
        elif name == "lit":
            try:
                az, el = value.split(",")
                kw["lit"] = (float(az), float(el))
            except ValueError:
                raise Usage(f"--lit: '{value}' is not AZ,EL in degrees") from None
        elif name == "maps":
            kw["maps"] = tuple(value.split(","))
        elif name in ("keep-going", "force", "nomip", "fast-compression"):
            kw[key] = True
        elif name in ("texture-format", "vtf-version", "vtf-flags", "vmt", "materials",
                      "basetexture"):
            kw[key] = value  # parsed by the library, as the C CLI parses them
    return kw, outputs


def _print_report(report, as_json, quiet, batch):
    if report.status == "failed":
        print(f"bumpbake: {report.error}", file=sys.stderr)
    if report.status == "not run":
        return
    if as_json:
        line = {"input": report.input}
        if batch or report.status != "baked":
            line["status"] = report.status
        if report.status == "baked":
            line.update(width=report.width, height=report.height,
                        parameters={"slices": report.slices, "rayset": report.rayset,
                                    "channel": report.channel, "threads": report.threads},
                        seconds=report.seconds, horizons=report.horizons)
            if report.cluster:
                line["cluster"] = report.cluster
        elif report.status == "failed":
            line["exit_code"] = 1
        line["outputs"] = [{"kind": k, "path": p} for k, p in report.outputs.items()
                           if not k.startswith("slope") or report.status != "baked"]
        print(json.dumps(line, separators=(",", ":")))
    elif not quiet and report.status in ("baked", "up to date"):
        verb = "wrote" if report.status == "baked" else "up to date"
        for kind, path in report.outputs.items():
            print(f"{verb} {kind} {path}")
    sys.stdout.flush()


def _summary(reports, as_json, quiet):
    count = {s: sum(r.status == s for r in reports)
             for s in ("baked", "up to date", "failed", "not run")}
    if as_json:
        print(json.dumps({"summary": {"files": len(reports), "baked": count["baked"],
                                      "up_to_date": count["up to date"],
                                      "failed": count["failed"],
                                      "not_run": count["not run"]}}, separators=(",", ":")))
    elif not quiet:
        line = (f"bake: {len(reports)} file{'' if len(reports) == 1 else 's'}: "
                f"{count['baked']} baked, {count['up to date']} up to date, "
                f"{count['failed']} failed")
        if count["not run"]:
            line += (f", {count['not run']} not run (stopped at the first failure; "
                     "--keep-going goes on)")
        print(line)


def bake(args):
    """`bake` with args as typed; returns the exit code."""
    options, positionals, scheduler_words = parse(args)
    names = {name for name, _, _ in options}
    if "help" in names:
        print(USAGE, end="")
        return 0
    values = {name: value for name, value, _ in options}
    if "scheduler" not in values:
        raise Usage("--scheduler ADDRESS is required (the Dask scheduler, tcp://host:8786)")
    if "scale" not in values:
        raise Usage("--scale is required (texels of displacement per unit of height)")
    if not positionals:
        raise Usage("missing HEIGHT")
    kw, outputs = _bake_arguments(options)
    as_json, quiet = "json" in names, "quiet" in names
    from . import bake_big, bake_files
    from ._connect import connect
    with connect(values["scheduler"], quiet=True) as client:
        if "out-dir" in values:
            if outputs or "prefix" in kw or "slope" in kw:
                raise Usage("-o, --normal FILE ... and --slope are for a single bake; a batch "
                            "names its outputs with --maps and --name")
            kw.pop("lit", None)
            out_dir = values["out-dir"]
            reports = bake_files(positionals, out_dir, client=client, check=False,
                                 notes=_note, command_options=" ".join(_command_words(options)),
                                 **kw)
            for r in reports:
                _print_report(r, as_json, quiet, batch=True)
            _summary(reports, as_json, quiet)
            return 1 if any(r.status == "failed" for r in reports) else 0
        if len(positionals) > 1:
            raise Usage("several HEIGHT files need --out-dir DIR")
        for key in ("maps", "name", "keep_going", "force"):
            if key in kw:
                raise Usage(f"--{key.replace('_', '-')} is for batches: give --out-dir DIR")
        # the whole command as typed, as the CLI records it, without --scheduler
        command = " ".join(["bumpbake", "bake"] + [w for i, w in enumerate(args)
                                                   if i not in scheduler_words])
        report = bake_big(positionals[0], outputs or None, client=client, check=False,
                          notes=_note, command=command, **kw)
        _print_report(report, as_json, quiet, batch=False)
        return 1 if report.status == "failed" else 0


def _note(line):
    print(f"bumpbake: {line.split(': ', 1)[0]}: note: {line.split(': ', 1)[-1]}"
          if ": " in line else f"bumpbake: note: {line}", file=sys.stderr)


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    if not argv or argv[0] in ("-h", "--help"):
        print(USAGE, end="")
        return 0 if argv else 2
    if argv[0] != "bake":
        print(f"bumpbake: unknown command '{argv[0]}' (python3 -m bumpbake.dask bake ...)",
              file=sys.stderr)
        return 2
    try:
        return bake(argv[1:])
    except Usage as e:
        print(f"bumpbake bake: {e}", file=sys.stderr)
        return 2
    except ArgumentError as e:
        print(f"bumpbake bake: {e}", file=sys.stderr)
        return 2
    except Error as e:
        print(f"bumpbake: {e}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        return 130
