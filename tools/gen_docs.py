#!/usr/bin/python3
"""gen_docs.py: the command reference's option tables and the man page, from --help.

    tools/gen_docs.py [BIN]           rewrite docs/commands/*.md and docs/bumpbake.1
    tools/gen_docs.py --check [BIN]   exit 1, naming the command, where a page or
                                      the man page differs from what would be written

BIN is the bumpbake to ask (default build/bumpbake). `make docs-reference`
runs the first form, `make check-docs` (part of `make test`) the second.

What comes from where, so the reference cannot drift from the program:
- each page docs/commands/COMMAND.md keeps, between the lines
  `<!-- generated: options -->` and `<!-- end generated -->`, the usage line
  and the options table of `bumpbake COMMAND --help`; everything else on the
  page is written by hand;
- docs/commands/README.md keeps, between `<!-- generated: commands -->` and
  `<!-- end generated -->`, the table of commands of `bumpbake --help`;
- docs/bumpbake.1 is made whole: its NAME and SYNOPSIS from --help, its
  DESCRIPTION, EXIT STATUS and ENVIRONMENT from docs/commands/README.md
  (the first paragraph and the sections of those names), and for each
  command its page's first paragraph and its options from --help.

Debian's python3 alone; no third-party module.
"""

import difflib
import os
import re
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PAGES = os.path.join(ROOT, "docs", "commands")
INDEX = os.path.join(PAGES, "README.md")
MAN = os.path.join(ROOT, "docs", "bumpbake.1")
BEGIN_OPTIONS = "<!-- generated: options -->"
BEGIN_COMMANDS = "<!-- generated: commands -->"
END = "<!-- end generated -->"


class DocsError(Exception):
    pass


# ------------------------------------------------------------------ --help


def run_help(binary, *args):
    try:
        p = subprocess.run([binary, *args, "--help"], capture_output=True, text=True,
                           env=dict(os.environ, LC_ALL="C"))
    except OSError as e:
        raise DocsError("cannot run %s: %s (build it with make)" % (binary, e.strerror))
    if p.returncode != 0:
        raise DocsError("%s %s --help exited %d: %s" % (binary, " ".join(args), p.returncode,
                                                       p.stderr.strip()))
    return p.stdout


def parse_top(text):
    """`bumpbake --help`: the one-paragraph description and the commands."""
    lines = text.splitlines()
    description, commands, i = [], [], 1
    while i < len(lines) and lines[i].strip():
        description.append(lines[i].strip())
        i += 1
    on = False
    for line in lines:
        if line.startswith("commands:"):
            on = True
        elif on and not line.strip():
            break
        elif on:
            name, summary = line.split(None, 1)
            commands.append((name, summary.strip()))
    if not commands:
        raise DocsError("bumpbake --help lists no commands")
    return " ".join(description), commands


class Option:
    def __init__(self, flags, text):
        self.flags = flags
        m = re.match(r"^(.*?)(?:; default (.*?))?(?:; range (.*))?$", text)
        self.help, self.default, self.range = m.group(1), m.group(2), m.group(3)
        # "-o, --output OUT": the names, then the value's words.
        words = flags.split(" ")
        names = []
        while words and words[0].startswith("-"):
            names.append(words.pop(0).rstrip(","))
        self.names, self.value = names, " ".join(words)


def parse_command(name, text):
    """`bumpbake NAME --help`: the usage line, the summary and the options."""
    lines = text.splitlines()
    prefix = "usage: bumpbake %s " % name
    if not lines or not lines[0].startswith(prefix):
        raise DocsError("bumpbake %s --help does not start with '%s'" % (name, prefix.strip()))
    usage = lines[0][len("usage: "):]
    try:
        start = lines.index("options:") + 1
    except ValueError:
        raise DocsError("bumpbake %s --help has no 'options:' line" % name)
    options = []
    for line in lines[start:]:
        # "  FLAGS  TEXT": the flags never hold two spaces in a row, and --help
        # ends them with at least two (padding them to a column when they fit).
        m = re.match(r"^  (-\S+(?: \S+)*)  +(\S.*)$", line)
        if not m:
            raise DocsError("bumpbake %s --help: cannot read the line '%s'" % (name, line))
        options.append(Option(m.group(1), m.group(2).strip()))
    return usage, options


# ---------------------------------------------------------------- markdown


def md_cell(text):
    """Plain --help text as a table cell: pipes and asterisks escaped."""
    return text.replace("\\", "\\\\").replace("|", "\\|").replace("*", "\\*")


def md_code(text):
    """Text as a code span inside a table cell (pipes still need escaping)."""
    return "`%s`" % text.replace("|", "\\|")


def options_block(name, usage, options):
    out = [BEGIN_OPTIONS,
           "<!-- from `bumpbake %s --help` by tools/gen_docs.py (`make docs-reference`); "
           "edit the option rows in src/cmd/options_*.c, not here -->" % name,
           "",
           "```",
           usage,
           "```",
           "",
           "| option | default | range | meaning |",
           "|---|---|---|---|"]
    for o in options:
        out.append("| %s | %s | %s | %s |" % (md_code(o.flags), md_cell(o.default or ""),
                                             md_cell(o.range or ""), md_cell(o.help)))
    out.append(END)
    return "\n".join(out)


def commands_block(commands):
    out = [BEGIN_COMMANDS,
           "<!-- from `bumpbake --help` by tools/gen_docs.py (`make docs-reference`) -->",
           "",
           "| command | what it does |",
           "|---|---|"]
    for name, summary in commands:
        out.append("| [`%s`](%s.md) | %s |" % (name, name, md_cell(summary)))
    out.append(END)
    return "\n".join(out)


def replace_block(path, text, begin, block):
    """text with the lines from begin to END replaced by block."""
    a = text.find(begin)
    b = text.find(END, a if a >= 0 else 0)
    if a < 0 or b < 0 or (a > 0 and text[a - 1] != "\n"):
        raise DocsError("%s: no '%s' ... '%s' lines to fill" % (rel(path), begin, END))
    return text[:a] + block + text[b + len(END):]


def first_paragraph(path, text):
    """The page's own short description: its first paragraph after the title."""
    lines = text.splitlines()
    i = 0
    while i < len(lines) and (not lines[i].strip() or lines[i].startswith("#")):
        i += 1
    para = []
    while i < len(lines) and lines[i].strip():
        para.append(lines[i].strip())
        i += 1
    if not para or para[0].startswith("<!--"):
        raise DocsError("%s: no paragraph after the title to describe the command" % rel(path))
    return " ".join(para)


def section(path, text, title, required=True):
    """The body of the '## title' section."""
    m = re.search(r"^## %s\n(.*?)(?=^## |\Z)" % re.escape(title), text, re.M | re.S)
    if not m:
        if required:
            raise DocsError("%s: no '## %s' section" % (rel(path), title))
        return ""
    return m.group(1).strip()


# ------------------------------------------------------------------- roff

ROFF_CHARS = {"\u00d7": "\\(mu", "\u00b0": "\\(de", "\u00b2": "\\(S2", "\u2014": "\\(em",
              "\u2013": "\\(en", "\u2019": "'", "\u2264": "\\(<=", "\u2265": "\\(>=",
              "\u00b1": "\\(+-", "\u2192": "\\(->"}


def roff_text(text):
    """Plain text escaped for roff: backslashes, minus signs, non-ASCII."""
    out = []
    for ch in text.replace("\\", "\\e").replace("-", "\\-"):
        if ord(ch) < 128:
            out.append(ch)
        elif ch in ROFF_CHARS:
            out.append(ROFF_CHARS[ch])
        else:
            raise DocsError("no roff spelling for the character %r (add it to ROFF_CHARS)" % ch)
    return "".join(out)


def link_text(m):
    """A markdown link as man page text: a link to another page of docs/
    names the file (the man page has no links), one within the command
    reference or to a web page keeps its text alone; a picture is left out."""
    if m.group(1):
        return ""
    text, target = m.group(2), m.group(3).split("#")[0]
    if not target.endswith(".md"):
        return text
    path = os.path.normpath(os.path.join(PAGES, target))
    return text if path == INDEX else "%s (%s)" % (text, rel(path))


def roff_inline(md):
    """One line of markdown as roff: code and bold in bold, links as text."""
    out = []
    md = re.sub(r"(!?)\[([^\]]*)\]\(([^)]*)\)", link_text, md)
    for i, part in enumerate(re.split(r"(`[^`]*`)", md)):
        if i % 2:
            out.append("\\fB" + roff_text(part[1:-1].replace("\\|", "|")) + "\\fR")
            continue
        part = part.replace("\\|", "|").replace("\\*", "*").replace("\\_", "_")
        pieces = re.split(r"(\*\*[^*]+\*\*)", part)
        for j, p in enumerate(pieces):
            out.append("\\fB" + roff_text(p[2:-2]) + "\\fR" if j % 2 else roff_text(p))
    return "".join(out)


def roff_lines(text):
    """Lines of roff text; a line must not start with a control character."""
    out = []
    for line in text.split("\n"):
        line = line.strip()
        if line.startswith((".", "'")):
            line = "\\&" + line
        out.append(line)
    return out


def roff_blocks(md):
    """A markdown section (paragraphs, lists, simple tables, code) as roff."""
    out, lines, i = [], md.splitlines(), 0
    while i < len(lines):
        line = lines[i]
        if not line.strip() or line.lstrip().startswith("<!--"):
            i += 1
        elif line.startswith("```"):
            j = i + 1
            code = []
            while j < len(lines) and not lines[j].startswith("```"):
                code.append(lines[j])
                j += 1
            out += [".PP", ".RS", ".EX"]
            out += ["\\&" + roff_text(c) if c.startswith((".", "'")) else roff_text(c)
                    for c in code]
            out += [".EE", ".RE"]
            i = j + 1
        elif line.startswith("|"):
            rows = []
            while i < len(lines) and lines[i].startswith("|"):
                cells = [c.strip() for c in re.split(r"(?<!\\)\|", lines[i].strip())[1:-1]]
                if not all(re.fullmatch(r":?-+:?", c) for c in cells):
                    rows.append(cells)
                i += 1
            for cells in rows[1:]:  # the header row names the columns only
                out += [".TP", roff_lines(roff_inline(cells[0]))[0]]
                out += roff_lines(roff_inline("; ".join(c for c in cells[1:] if c)))
        elif re.match(r"^[-*] ", line):
            item = [line[2:]]
            i += 1
            while i < len(lines) and lines[i].startswith("  ") and lines[i].strip():
                item.append(lines[i].strip())
                i += 1
            out += [".IP \\(bu 2"] + roff_lines(roff_inline(" ".join(item)))
        else:
            para = []
            while i < len(lines) and lines[i].strip() and not lines[i].startswith(("|", "```")) \
                    and not re.match(r"^[-*] ", lines[i]):
                para.append(lines[i].strip())
                i += 1
            out += [".PP"] + roff_lines(roff_inline(" ".join(para)))
    return out


def roff_usage(usage):
    """A usage line: option names in bold, placeholders in italics."""
    words = []
    for w in usage.split(" "):
        m = re.match(r"^([\[(]*)(.*?)([\])]*\.*)$", w)
        lead, core, tail = m.groups()
        if core.startswith("-"):
            core = "\\fB" + roff_text(core) + "\\fR"
        elif core and core != "bumpbake" and not core.islower():
            core = "\\fI" + roff_text(core) + "\\fR"
        else:
            core = roff_text(core)
        words.append(roff_text(lead) + core + roff_text(tail))
    return " ".join(words)


def roff_option(o):
    tag = ", ".join("\\fB" + roff_text(n) + "\\fR" for n in o.names)
    if o.value:
        tag += " \\fI" + roff_text(o.value) + "\\fR"
    body = o.help[0].upper() + o.help[1:] if o.help else ""
    body = body.rstrip(".") + "."
    if o.default:
        body += " Default: " + o.default + "."
    if o.range:
        body += " Range: " + o.range + "."
    return [".TP", tag] + roff_lines(roff_text(body))


def man_page(description, commands, parsed, pages, index_text):
    out = [
        '.\\" bumpbake.1: the manual page of bumpbake. Generated by tools/gen_docs.py',
        '.\\" from `bumpbake --help`, each `bumpbake COMMAND --help` and',
        '.\\" docs/commands/*.md (`make docs-reference`); do not edit by hand.',
        '.TH BUMPBAKE 1 "" "bumpbake" "User Commands"',
        ".nh",
        ".ad l",
        ".SH NAME",
        "bumpbake \\- " + roff_text(description[0].lower() + description[1:].rstrip(".")),
        ".SH SYNOPSIS",
    ]
    for name, _ in commands:
        out += [roff_usage(parsed[name][0]), ".br"]
    out += ["\\fBbumpbake\\fR [\\fB\\-\\-help\\fR | \\fB\\-\\-version\\fR]",
            ".SH DESCRIPTION"]
    out += roff_blocks(first_paragraph(INDEX, index_text))
    out += roff_blocks(section(INDEX, index_text, "Inputs and outputs"))
    out.append(".SH COMMANDS")
    for name, _ in commands:
        usage, options = parsed[name]
        out += ['.SS "bumpbake %s"' % name, ".PP", roff_usage(usage)]
        out += roff_blocks(first_paragraph(pages[name][0], pages[name][1]))
        for o in options:
            out += roff_option(o)
        out += [".PP", "The full reference: \\fIdocs/commands/%s.md\\fR in the source tree." % name]
    out.append(".SH EXIT STATUS")
    out += roff_blocks(section(INDEX, index_text, "Exit codes"))
    out.append(".SH ENVIRONMENT")
    out += roff_blocks(section(INDEX, index_text, "Environment"))
    out += [".SH SEE ALSO",
            ".BR idiff (1),",
            ".BR oiiotool (1),",
            ".BR pkg\\-config (1).",
            ".PP",
            "The C library is documented in its header, \\fIbumpbake.h\\fR; the source tree's",
            "\\fIREADME.md\\fR and \\fIdocs/\\fR hold the guide and the full reference."]
    return "\n".join(out) + "\n"


# ------------------------------------------------------------------- main


def rel(path):
    return os.path.relpath(path, ROOT)


def read(path):
    try:
        with open(path, encoding="utf-8") as f:
            return f.read()
    except OSError as e:
        raise DocsError("%s: %s" % (rel(path), e.strerror))


def generate(binary):
    """{path: (text it should hold, the command it is about or None)}."""
    description, commands = parse_top(run_help(binary))
    names = [n for n, _ in commands]
    parsed = {n: parse_command(n, run_help(binary, n)) for n in names}
    on_disk = {f[:-3] for f in os.listdir(PAGES) if f.endswith(".md") and f != "README.md"}
    extra = sorted(on_disk - set(names))
    if extra:
        raise DocsError("docs/commands/ has pages of no command of --help: %s" % ", ".join(extra))
    result, pages = {}, {}
    for n in names:
        path = os.path.join(PAGES, n + ".md")
        if not os.path.exists(path):
            raise DocsError("bumpbake %s has no page: write %s with the markers %s and %s"
                            % (n, rel(path), BEGIN_OPTIONS, END))
        text = replace_block(path, read(path), BEGIN_OPTIONS, options_block(n, *parsed[n]))
        result[path] = (text, n)
        pages[n] = (path, text)
    index = replace_block(INDEX, read(INDEX), BEGIN_COMMANDS, commands_block(commands))
    result[INDEX] = (index, None)
    result[MAN] = (man_page(description, commands, parsed, pages, index), None)
    return result, names


def man_sections(text):
    """The man page cut at its command sections: {command or part: text}."""
    parts, key = {}, "head"
    for line in text.splitlines():
        m = re.match(r'^\.SS "bumpbake (\S+)"', line)
        if m:
            key = m.group(1)
        elif line.startswith(".SH ") and key != "head":
            key = line[4:]
        parts[key] = parts.get(key, "") + line + "\n"
    return parts


def check(result):
    stale = 0
    for path, (want, command) in result.items():
        have = read(path) if os.path.exists(path) else ""
        if have == want:
            continue
        stale += 1
        if path == MAN:
            a, b = man_sections(have), man_sections(want)
            changed = [k for k in sorted(set(a) | set(b)) if a.get(k) != b.get(k)]
            named = ["bumpbake %s" % k for k in changed if k not in ("head",) and k.islower()]
            print("gen_docs: %s differs from what --help and the pages make%s"
                  % (rel(path), ": the section of " + ", ".join(named) if named else ""),
                  file=sys.stderr)
        elif command:
            print("gen_docs: %s: the options differ from `bumpbake %s --help`"
                  % (rel(path), command), file=sys.stderr)
        else:
            print("gen_docs: %s: the commands differ from `bumpbake --help`" % rel(path),
                  file=sys.stderr)
        diff = list(difflib.unified_diff(have.splitlines(), want.splitlines(),
                                         "%s (committed)" % rel(path),
                                         "%s (from --help)" % rel(path), n=0, lineterm=""))
        for line in diff[:24]:
            print("  " + line, file=sys.stderr)
        if len(diff) > 24:
            print("  ... (%d more lines)" % (len(diff) - 24), file=sys.stderr)
    if stale:
        print("gen_docs: %d file(s) out of date; run `make docs-reference` and commit them"
              % stale, file=sys.stderr)
        return 1
    print("gen_docs: docs/commands/*.md and docs/bumpbake.1 agree with --help")
    return 0


def main(argv):
    args = argv[1:]
    check_only = "--check" in args
    args = [a for a in args if a != "--check"]
    if len(args) > 1 or any(a.startswith("-") for a in args):
        print(__doc__.split("\n\n")[1], file=sys.stderr)
        return 2
    binary = args[0] if args else os.path.join(ROOT, "build", "bumpbake")
    try:
        result, names = generate(binary)
        if check_only:
            return check(result)
        for path, (text, _) in result.items():
            if not os.path.exists(path) or read(path) != text:
                with open(path, "w", encoding="utf-8") as f:
                    f.write(text)
                print("gen_docs: wrote %s" % rel(path))
    except DocsError as e:
        print("gen_docs: %s" % e, file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
