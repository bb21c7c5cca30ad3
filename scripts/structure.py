#!/usr/bin/env python3
"""Structural checks of the source tree, run by the test suite
(tests/structure.rs):

- every function in src/ is at most MAX_FN_LINES lines long;
- no import circle, between files nor between folders at any level;
- no effect name of the diagnosis is written as a string outside
  src/diagnose/effects/ (src/scene/ excepted: some scene keys share an
  effect's name); the names are read from the registry, `ALL` in
  src/diagnose/effects/mod.rs, and each listed effect's `name()`;
- no file name of the run directory is written as a string outside
  src/rundir/, not even inside a message or a format string; the names
  are read from rundir's `pub const NAME: &str` constants and its name
  functions (`fn …(…) -> String { format!("…") }`, whose placeholders
  match any word). Names without an extension (`figures`, `stage1`) count
  only as a whole string: as words they are also prose;
- no constant outside src/rundir/ holds a file name of the kinds a run
  writes (`const X: &str = "name.json"`, .png, .bmp, .txt, .tsv, .log,
  .html, .svg): a run's file names have one owner.

The import graph. Every file is a module: src/a/b.rs is `a::b`, a folder's
mod.rs is the folder's module `a`, src/lib.rs the crate root (src/main.rs
is another crate and is left out). What lies in a file's `#[cfg(test)]`
module, in comments and in strings is left out. An edge A -> B means the
code of A needs an item that B defines:

- a `use` of an item (`use crate::x::Item;`, `use super::Item;`, a child's
  `use child::Item;`) is an edge to the module that defines the item;
  `use x::*` is an edge to x;
- a path in code (`crate::x::f()`, `super::x::T`, `child::f()`, or
  `alias::f()` through a module brought in by `use`) is an edge to the
  module that defines its item;
- a re-export (`pub use …`, `pub(crate) use …`) is no edge of its own: it
  is the folder's interface, not a need of its code. A path through a
  re-export is followed to the module that defines the item, so that
  `crate::scene::Scene` is an edge to scene/types.rs, not to scene/mod.rs.
  A re-exported name that the re-exporting file's own code uses is an edge;
- a `mod` declaration is no edge, nor is importing a module's name
  (`use crate::render::phong;`): only what is then used through it.

So a child's use of a type its parent mod.rs defines is an edge child ->
mod.rs, and the parent's code calling the child is an edge mod.rs -> child:
together a circle, broken by moving the type to a leaf module.

Circles are the strongly connected components of this graph with more than
one module, between files, and for every folder between its members (its
mod.rs and each of its files and sub-folders, a sub-folder taken whole).

Prints what it finds and exits 1 when anything is over the line.
Usage: python3 scripts/structure.py [--report] [--root DIR]
  --report: never fail; --root: check DIR/src instead of this tree's.
"""
import os
import re
import sys

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
SRC = os.path.join(ROOT, "src")
MAX_FN_LINES = 80
EFFECTS_MOD = os.path.join(SRC, "diagnose", "effects", "mod.rs")
RUNDIR = os.path.join(SRC, "rundir")


def rust_files():
    for d, dirs, files in os.walk(SRC):
        dirs.sort()
        for f in sorted(files):
            if f.endswith(".rs"):
                yield os.path.join(d, f)


def strip_tests(text):
    """The file without its #[cfg(test)] module (tests may name anything)."""
    m = re.search(r"#\[cfg\(test\)\]\s*mod tests", text)
    return text[: m.start()] if m else text


def scan(text):
    """(code, strings): the text with comments removed and string and char
    literals emptied (line numbers kept), and every string literal's
    (line, value)."""
    out, strings = [], []
    i, n, line = 0, len(text), 1
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            i = n if j < 0 else j
        elif text.startswith("/*", i):
            depth, j = 1, i + 2
            while j < n and depth:
                if text.startswith("/*", j):
                    depth, j = depth + 1, j + 2
                elif text.startswith("*/", j):
                    depth, j = depth - 1, j + 2
                else:
                    j += 1
            out.append("\n" * text.count("\n", i, j))
            line += text.count("\n", i, j)
            i = j
        elif c == '"' or (c == "r" and re.match(r'r#*"', text[i:i + 8])
                          and not (i and (text[i - 1].isalnum() or text[i - 1] == "_"))):
            i, line = string_literal(text, i, line, out, strings)
        elif c == "'":
            m = re.match(r"'(\\u\{[0-9a-fA-F]+\}|\\.|[^\\'])'", text[i:i + 12])
            if m:
                out.append("''")
                i += m.end()
            else:
                out.append(c)
                i += 1
        else:
            if c == "\n":
                line += 1
            out.append(c)
            i += 1
    return "".join(out), strings


def string_literal(text, i, line, out, strings):
    """Reads the string literal at i (plain or raw); returns (end, line)."""
    start_line = line
    if text[i] == "r":
        hashes = re.match(r"r(#*)\"", text[i:]).group(1)
        close = '"' + hashes
        body_start = i + 2 + len(hashes)
        j = text.find(close, body_start)
        j = len(text) if j < 0 else j
        value, end = text[body_start:j], j + len(close)
    else:
        j = i + 1
        while j < len(text) and text[j] != '"':
            j += 2 if text[j] == "\\" else 1
        value, end = text[i + 1:j], j + 1
    strings.append((start_line, value))
    nl = value.count("\n")
    out.append('""' + "\n" * nl)
    return end, line + nl


# ---------------------------------------------------------------- functions

def long_functions():
    found = []
    for path in rust_files():
        code, _ = scan(strip_tests(open(path).read()))
        lines = code.split("\n")
        i = 0
        while i < len(lines):
            m = re.match(r"\s*(pub(\([^)]*\))?\s+)?(const\s+)?(async\s+)?(unsafe\s+)?fn\s+(\w+)", lines[i])
            if not m:
                i += 1
                continue
            depth, started, j = 0, False, i
            while j < len(lines):
                depth += lines[j].count("{") - lines[j].count("}")
                if "{" in lines[j]:
                    started = True
                if started and depth <= 0:
                    break
                if not started and lines[j].rstrip().endswith(";"):
                    break
                j += 1
            n = j - i + 1
            if started and n > MAX_FN_LINES:
                found.append((n, os.path.relpath(path, ROOT), i + 1, m.group(6)))
            i = j + 1 if started else i + 1
    return sorted(found, reverse=True)


# ---------------------------------------------------------------- modules

ITEM = re.compile(
    r"^(?:pub(?:\([^)]*\))?\s+)?(?:(?:unsafe|async|const|extern\s+\"\w*\")\s+)*"
    r"(?:fn|struct|enum|trait|type|const|static|union|mod)\s+(\w+)", re.M)
USE = re.compile(r"^[ \t]*(pub(?:\([^)]*\))?\s+)?use\s+([^;]+);", re.M)
PATH = re.compile(r"(?<![\w:])((?:\w+::)+\w+)")


def module_path(path):
    """The module a file is: src/a/b.rs -> ("a", "b"); src/a/mod.rs -> ("a",)."""
    parts = os.path.relpath(path, SRC)[:-3].split(os.sep)
    if parts[-1] == "mod" or parts == ["lib"]:
        parts = parts[:-1]
    return tuple(parts)


def use_tree(text):
    """The leaves of a use tree: (segments, local name, glob)."""
    tokens = re.findall(r"::|[{},*]|\w+", text)
    leaves = []

    def walk(k, prefix):
        segs = list(prefix)
        while k < len(tokens):
            t = tokens[k]
            if t == "{":
                k += 1
                while tokens[k] != "}":
                    k = walk(k, segs)
                    if tokens[k] == ",":
                        k += 1
                return k + 1
            if t == "*":
                leaves.append((segs, None, True))
                return k + 1
            if t in (",", "}"):
                break
            if t != "::":
                segs.append(t)
            k += 1
            if k < len(tokens) and tokens[k] == "as":
                leaves.append((segs, tokens[k + 1], False))
                return k + 2
        if segs and segs != list(prefix):
            name = segs[-1] if segs[-1] != "self" else segs[-2]
            leaves.append((segs, name, False))
        return k

    k = 0
    while k < len(tokens):
        k = walk(k, [])
        if k < len(tokens) and tokens[k] == ",":
            k += 1
    return leaves


class Module:
    def __init__(self, path):
        self.file = os.path.relpath(path, ROOT)
        raw = strip_tests(open(path).read())
        self.code, self.strings = scan(raw)
        self.items = set(ITEM.findall(self.code))
        self.uses = []  # (segments, local name, glob, public, line)
        for m in USE.finditer(self.code):
            line = self.code.count("\n", 0, m.start()) + 1
            for segs, name, glob in use_tree(m.group(2)):
                self.uses.append((segs, name, glob, bool(m.group(1)), line))
        self.body = USE.sub(lambda m: "\n" * m.group(0).count("\n"), self.code)


def load_modules():
    mods = {}
    for path in rust_files():
        if os.path.relpath(path, SRC) == "main.rs":
            continue
        mods[module_path(path)] = Module(path)
    return mods


class Resolver:
    """Resolves a path written in a module to the module defining its item."""

    def __init__(self, mods):
        self.mods = mods

    def children(self, mod):
        return {m[-1] for m in self.mods if len(m) == len(mod) + 1 and m[:-1] == mod}

    def alias(self, mod, name):
        for segs, local, glob, _, _ in self.mods[mod].uses:
            if not glob and local == name:
                return segs
        return None

    def resolve(self, mod, segs, seen=()):
        """("module", m) or ("item", m) for a path in crate code, or None."""
        if (mod, tuple(segs)) in seen or not segs:
            return None
        seen = seen + ((mod, tuple(segs)),)
        first = segs[0]
        if first == "crate":
            return self.walk((), segs[1:], seen)
        if first == "super":
            cur, k = mod, 0
            while k < len(segs) and segs[k] == "super":
                cur, k = cur[:-1], k + 1
            return self.walk(cur, segs[k:], seen)
        if first == "self":
            return self.walk(mod, segs[1:], seen)
        if first in self.children(mod):
            return self.walk(mod + (first,), segs[1:], seen)
        target = self.alias(mod, first)
        if target is None:
            return None
        got = self.resolve(mod, target, seen)
        if got is None or len(segs) == 1:
            return got
        if got[0] == "module":
            return self.walk(got[1], segs[1:], seen)
        return got

    def walk(self, cur, rest, seen):
        while rest and rest[0] in self.children(cur):
            cur, rest = cur + (rest[0],), rest[1:]
        if not rest or rest == ["self"]:
            return ("module", cur)
        if cur not in self.mods:
            return None
        name = rest[0]
        if name not in self.mods[cur].items and self.alias(cur, name) is not None:
            got = self.resolve(cur, self.alias(cur, name), seen)
            if got is not None and got[0] == "module" and len(rest) > 1:
                return self.walk(got[1], rest[1:], seen)
            if got is not None:
                return ("item", got[1])
        return ("item", cur)


def edges_of(mod, m, res):
    """{target module: (line, what)} for the edges of one module."""
    found = {}

    def add(got, line, what):
        if got is None or got[1] == mod or got[1] not in res.mods:
            return
        if got[0] == "item" or what.endswith("*"):
            found.setdefault(got[1], (line, what))

    for segs, name, glob, public, line in m.uses:
        got = res.resolve(mod, segs)
        if glob:
            add(got and ("item", got[1]), line, "use " + "::".join(segs) + "::*")
        elif not public or re.search(r"\b%s\b" % re.escape(name), m.body):
            add(got, line, "use " + "::".join(segs))
    for k, text in enumerate(m.body.split("\n")):
        for p in PATH.findall(text):
            add(res.resolve(mod, p.split("::")), k + 1, p)
    return found


def graph():
    mods = load_modules()
    res = Resolver(mods)
    return mods, {mod: edges_of(mod, m, res) for mod, m in mods.items()}


def sccs(nodes, succ):
    """Strongly connected components with more than one node (Tarjan)."""
    index, low, stack, on, out = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in sorted(succ.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in sorted(nodes):
        if v not in index:
            visit(v)
    return out


def name(mod):
    return "crate" if not mod else "::".join(mod)


def file_circles(mods, edges):
    """Each circle between files: the edges inside it, with where."""
    succ = {a: set(e) for a, e in edges.items()}
    found = []
    for comp in sccs(mods, succ):
        inner = [(a, b, edges[a][b]) for a in comp for b in sorted(edges[a]) if b in comp]
        found.append((comp, inner))
    return found


def folder_circles(mods, edges):
    """Each circle between the members of a folder (sub-folders whole)."""
    def is_folder(m):
        return any(len(o) > len(m) and o[:len(m)] == m for o in mods)

    found = []
    for folder in sorted(m for m in mods if is_folder(m)):
        def member(m):
            if m[:len(folder)] != folder:
                return None
            return ("mod.rs",) if m == folder else (m[len(folder)],)
        succ, where = {}, {}
        for a, e in edges.items():
            for b, at in e.items():
                ma, mb = member(a), member(b)
                if ma and mb and ma != mb:
                    succ.setdefault(ma, set()).add(mb)
                    where.setdefault((ma, mb), (a, b, at))
        for comp in sccs(succ, succ):
            # Among files alone a circle is one between files, listed above.
            if any(is_folder(folder + c) for c in comp if c != ("mod.rs",)):
                inner = [where[(a, b)] for a in comp for b in sorted(succ.get(a, ())) if b in comp]
                found.append((folder, comp, inner))
    return found


# ---------------------------------------------------------------- names

def effect_names():
    """The names of the effects listed in the registry `ALL`."""
    mods = load_modules()
    res = Resolver(mods)
    reg = ("diagnose", "effects")
    body = re.search(r"\bALL\b[^=]*=\s*&\[(.*?)\];", mods[reg].code, re.S)
    if not body:
        sys.exit("scripts/structure.py: no `ALL` registry in " + EFFECTS_MOD)
    names = []
    for path in re.findall(r"&\s*([\w:]+)", body.group(1)):
        got = res.resolve(reg, path.split("::"))
        m = mods[got[1]] if got else None
        fn = m and re.search(r"fn name\(&self\)[^{]*\{\s*(\"\"|[\w:]+)\s*\}", m.code)
        if not fn:
            sys.exit(f"scripts/structure.py: no name() for {path} in the effects registry")
        names.append(literal_of(m, fn, res, mods, got[1]))
    return names


def literal_of(m, fn, res, mods, mod):
    """The string a `name()` returns: its literal, or the const it names."""
    if fn.group(1) == '""':
        line = m.code.count("\n", 0, fn.start(1)) + 1
        return next(v for ln, v in m.strings if ln == line)
    segs = fn.group(1).split("::")
    got = res.resolve(mod, segs) if len(segs) > 1 else ("item", mod)
    c = mods[got[1]]
    k = re.search(r"const %s: &(?:'static )?str = (\"\")" % segs[-1], c.code)
    line = c.code.count("\n", 0, k.start(1)) + 1
    return next(v for ln, v in c.strings if ln == line)


def run_file_names():
    """rundir's file names (exact) and name patterns (regexes)."""
    names, patterns = set(), []
    for f in sorted(os.listdir(RUNDIR)):
        if not f.endswith(".rs"):
            continue
        m = Module(os.path.join(RUNDIR, f))
        for k in re.finditer(r"pub const \w+: &(?:'static )?str = (\"\");", m.code):
            line = m.code.count("\n", 0, k.start(1)) + 1
            names.add(next(v for ln, v in m.strings if ln == line))
        for k in re.finditer(r"pub fn \w+\([^)]*\) -> String \{\s*format!\((\"\")", m.code):
            line = m.code.count("\n", 0, k.start(1)) + 1
            fmt = next(v for ln, v in m.strings if ln == line)
            parts = re.split(r"\{[^}]*\}", fmt)
            patterns.append(re.compile(r"(?<![\w.-])" + r"[^\s/]+".join(re.escape(p) for p in parts)
                                       + r"(?!\w)"))
    return names, patterns


def names_a_run_file(names, patterns):
    """Whether a string literal spells a run file's name: is one of the
    names, or holds a file name (one with an extension) or a name
    function's pattern as a word, in a message or a format string too."""
    files = [re.compile(r"(?<![\w.-])" + re.escape(n) + r"(?!\w)") for n in names if "." in n]

    def match(s):
        return s in names or any(p.search(s) for p in files + patterns)
    return match


FILE_CONST = re.compile(r'const (\w+): &(?:\'static )?str = ""')
FILE_NAME = re.compile(r"[\w.-]+\.(?:json|png|bmp|txt|tsv|log|html|svg)\Z")


def file_constants_outside_rundir():
    """Constants outside src/rundir/ whose value is a file name."""
    found = []
    for path in rust_files():
        rel = os.path.relpath(path, ROOT)
        if rel.startswith(os.path.relpath(RUNDIR, ROOT) + os.sep):
            continue
        m = Module(path)
        for k in FILE_CONST.finditer(m.code):
            line = m.code.count("\n", 0, k.start()) + 1
            value = next((v for ln, v in m.strings if ln == line), "")
            if FILE_NAME.match(value):
                found.append((rel, line, k.group(1), value))
    return found


def strings_outside(match, allowed_dirs):
    found = []
    for path in rust_files():
        rel = os.path.relpath(path, ROOT)
        if any(rel.startswith(d + os.sep) for d in allowed_dirs):
            continue
        _, strings = scan(strip_tests(open(path).read()))
        for line, s in strings:
            if match(s):
                found.append((rel, line, s))
    return found


# ---------------------------------------------------------------- main

def report_circles():
    mods, edges = graph()
    files = file_circles(mods, edges)
    print(f"import circles between files: {len(files)}")
    for comp, inner in files:
        print("  " + " , ".join(name(c) for c in comp))
        for a, b, (line, what) in inner:
            print(f"    {name(a)} -> {name(b)}  ({mods[a].file}:{line} {what})")
    folders = folder_circles(mods, edges)
    print(f"import circles between the members of a folder: {len(folders)}")
    for folder, comp, inner in folders:
        print(f"  in {name(folder)}: " + " , ".join("/".join(c) for c in comp))
        for a, b, (line, what) in inner:
            print(f"    {name(a)} -> {name(b)}  ({mods[a].file}:{line} {what})")
    return bool(files or folders)


def set_root(root):
    global ROOT, SRC, EFFECTS_MOD, RUNDIR
    ROOT = root
    SRC = os.path.join(ROOT, "src")
    EFFECTS_MOD = os.path.join(SRC, "diagnose", "effects", "mod.rs")
    RUNDIR = os.path.join(SRC, "rundir")


def main():
    report_only = "--report" in sys.argv
    if "--root" in sys.argv:
        set_root(os.path.abspath(sys.argv[sys.argv.index("--root") + 1]))
    fns = long_functions()
    print(f"functions over {MAX_FN_LINES} lines: {len(fns)}")
    for n, f, line, fname in fns:
        print(f"  {n:4} {f}:{line} {fname}")
    circles = report_circles()
    effects = effect_names()
    # The scene's own keys (`ambient`, `fresnel`, ...) share some names
    # with effects: src/scene/ spells keys, not effects.
    eff = strings_outside(lambda s: s in effects, [os.path.join("src", "diagnose", "effects"),
                                                   os.path.join("src", "scene")])
    print(f"effect names ({len(effects)}, from effects::ALL) as strings outside "
          f"src/diagnose/effects/: {len(eff)}")
    for f, line, s in eff:
        print(f"  {f}:{line} \"{s}\"")
    names, patterns = run_file_names()
    run = strings_outside(names_a_run_file(names, patterns), [os.path.join("src", "rundir")])
    print(f"run-directory file names ({len(names)} names, {len(patterns)} patterns, from "
          f"src/rundir/) as strings outside src/rundir/: {len(run)}")
    for f, line, s in run:
        print(f"  {f}:{line} \"{s}\"")
    consts = file_constants_outside_rundir()
    print(f"file-name constants outside src/rundir/: {len(consts)}")
    for f, line, cname, value in consts:
        print(f"  {f}:{line} {cname} = \"{value}\"")
    bad = bool(fns or circles or eff or run or consts)
    sys.exit(0 if report_only or not bad else 1)


if __name__ == "__main__":
    main()
