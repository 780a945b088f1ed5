#!/usr/bin/env python3
"""The shape of sepval's source, checked by .ci/run (ARCHITECTURE.md, "Invariants"):

1. no source file over FILE_MAX lines and no function over FN_MAX lines, outside tests (files
   named *tests.rs or *fuzz*.rs and `#[cfg(test)]` modules are left out); a function that must
   stay long (a numeric kernel, a table of constants) says why in a comment line starting with
   `// shape: long` just above it, among its doc comments and attributes;
2. no module cycle within a crate: files are nodes, `crate::`, `super::` and `self::` paths edges
   to the file that defines the module, and modules are folded to each crate's top modules as
   well (a cycle between two folders is a cycle too); the effect plug-ins and the model that
   lists them are the one intended exception (a registry);
3. the crates depend on each other one way only, as ARCHITECTURE.md draws them: each crate's
   `sepval-*` dependencies (normal, not dev) are within the set it may use;
4. ARCHITECTURE.md's table of crates (the fenced `crates` block: one line per crate,
   `name (folder): the sepval crates it depends on`) is the truth: every crate it names is a
   workspace member in that folder, every member is in it, each line's dependencies are that
   crate's `Cargo.toml` dependencies and its MAY_USE entry, every `sepval-*` name in the page
   is a crate, and a sentence "X depends on Y" there names a dependency in X's Cargo.toml;
5. a crate whose library or binary says `test = false` (no unit-test harness: its compile in
   test mode is skipped, which CI's time needs) has no `#[test]` in its sources, since such a
   test would never run.

Usage: scripts/shape.py [ROOT]. Prints what breaks a rule and exits 1 if anything does.
"""
import os
import re
import sys

FILE_MAX = 600
FN_MAX = 100
# A crate may depend on these sepval crates and no other (ARCHITECTURE.md).
MAY_USE = {
    "sepval-core": set(),
    "sepval-common": {"sepval-core"},
    "sepval-transport": {"sepval-core", "sepval-common"},
    "sepval-solve": {"sepval-core"},
    "sepval-report": {"sepval-core"},
    # What every run shares (its directory, its inputs, its sealed records, the flight domain):
    # below every pipeline, so that none has to learn the fit to read a record.
    "sepval-run": {"sepval-core", "sepval-common", "sepval-solve"},
    "sepval-fit": {"sepval-core", "sepval-common", "sepval-solve", "sepval-run", "sepval-report"},
    "sepval-diagnose": {"sepval-core", "sepval-common", "sepval-solve", "sepval-run", "sepval-fit",
                        "sepval-report"},
    "sepval-plan": {"sepval-core", "sepval-common", "sepval-solve", "sepval-run", "sepval-fit",
                    "sepval-diagnose", "sepval-report"},
    "sepval-geometry": set(),
    "sepval-predict": {"sepval-core", "sepval-common", "sepval-solve", "sepval-run", "sepval-fit",
                       "sepval-diagnose", "sepval-report", "sepval-geometry"},
    "sepval-envelope": {"sepval-core", "sepval-common", "sepval-solve", "sepval-run",
                        "sepval-predict", "sepval-geometry", "sepval-report"},
    "sepval-update": {"sepval-core", "sepval-common", "sepval-solve", "sepval-run", "sepval-fit",
                      "sepval-diagnose", "sepval-report", "sepval-daveml"},
    # The store's data with uncertainty (DAVE-ML) and its estimate from its shape are priors a
    # campaign begins from.
    "sepval-campaign": {"sepval-core", "sepval-common", "sepval-solve", "sepval-run", "sepval-fit",
                        "sepval-diagnose", "sepval-predict", "sepval-envelope", "sepval-report",
                        "sepval-daveml", "sepval-aero"},
    "sepval": {"sepval-core", "sepval-common", "sepval-transport", "sepval-solve", "sepval-run",
               "sepval-fit", "sepval-diagnose", "sepval-plan", "sepval-predict", "sepval-envelope",
               "sepval-update", "sepval-campaign", "sepval-geometry", "sepval-report",
               "sepval-daveml", "sepval-aero"},
    "sepval-daveml": {"sepval-core", "sepval-common"},
    # The estimate from the shape: the store TOML's reader, the table form, the DAVE-ML export.
    "sepval-aero": {"sepval-core", "sepval-common", "sepval-geometry", "sepval-daveml"},
    "sepval-worker": {"sepval-core", "sepval-common", "sepval-transport"},
    # The Python package's extension module: the commands of the binary's library, the model
    # library's readers, the solvers' progress and the output directories' bookkeeping names.
    "sepval-python": {"sepval", "sepval-core", "sepval-common", "sepval-solve", "sepval-run"},
    "sepval-tests": set(),
}


def blank(src):
    """`src` with comments, strings and char literals replaced by spaces (lines kept)."""
    out, i, n = [], 0, len(src)
    while i < n:
        c = src[i]
        if src.startswith("//", i):
            j = src.find("\n", i)
            j = n if j < 0 else j
        elif src.startswith("/*", i):
            j = src.find("*/", i + 2)
            j = n if j < 0 else j + 2
        elif c == "r" and re.match(r'r#*"', src[i:i + 8]) and not (i and (src[i - 1].isalnum() or src[i - 1] == "_")):
            hashes = re.match(r'r(#*)"', src[i:i + 8]).group(1)
            j = src.find('"' + hashes, i + 2 + len(hashes))
            j = n if j < 0 else j + 1 + len(hashes)
        elif c == '"':
            j = i + 1
            while j < n and src[j] != '"':
                j += 2 if src[j] == "\\" else 1
            j += 1
        elif c == "'" and re.match(r"'(\\.|[^\\'])'", src[i:i + 4]) or re.match(r"'\\u\{[0-9a-fA-F]+\}'", src[i:i + 12]):
            j = src.find("'", i + 2) + 1
        else:
            out.append(c)
            i += 1
            continue
        out.append(re.sub(r"[^\n]", " ", src[i:j]))
        i = j
    return "".join(out)


def closing(text, open_at):
    """Index of the brace that closes the one at `open_at`."""
    depth = 0
    for k in range(open_at, len(text)):
        if text[k] == "{":
            depth += 1
        elif text[k] == "}":
            depth -= 1
            if depth == 0:
                return k
    return len(text) - 1


def without_tests(text):
    """`text` with every `#[cfg(test)]` module blanked (lines kept)."""
    for m in reversed(list(re.finditer(r"#\[cfg\(test\)\]\s*(pub(\([^)]*\))?\s+)?mod\s+\w+\s*\{", text))):
        end = closing(text, m.end() - 1)
        text = text[:m.start()] + re.sub(r"[^\n]", " ", text[m.start():end + 1]) + text[end + 1:]
    return text


def sources(root):
    for d, dirs, files in os.walk(root):
        dirs[:] = sorted(x for x in dirs if x not in ("target", ".git") and not x.startswith("."))
        if "Cargo.toml" in files and os.path.isdir(os.path.join(d, "src")):
            yield d


def rust_files(src):
    for d, _, files in os.walk(src):
        for f in sorted(files):
            if f.endswith(".rs") and not f.endswith("tests.rs") and "fuzz" not in f and f != "testing.rs":
                yield os.path.join(d, f)


def sizes(root, path, raw, problems):
    blanked = blank(raw)
    text = without_tests(blanked)
    lines = raw.split("\n")
    rel = os.path.relpath(path, root)
    # Lines outside test modules: a test module's lines are blank in `text` but not in `blanked`.
    in_tests = sum(1 for a, b in zip(blanked.split("\n"), text.split("\n")) if a.strip() and not b.strip())
    length = raw.count("\n") - in_tests
    if length > FILE_MAX:
        problems.append(f"file {rel}: {length} lines (limit {FILE_MAX})")
    for m in re.finditer(r"\bfn\s+(\w+)[^;{]*\{", text):
        start = text.count("\n", 0, m.start())
        end = text.count("\n", 0, closing(text, m.end() - 1))
        if end - start + 1 <= FN_MAX:
            continue
        k = start - 1
        excused = False
        while k >= 0 and re.match(r"\s*(///|//|#\[|#!\[)", lines[k]):
            excused |= lines[k].strip().startswith("// shape: long")
            k -= 1
        if not excused:
            problems.append(f"fn {rel}:{start + 1} {m.group(1)}: {end - start + 1} lines (limit {FN_MAX})")


def module_of(src, path):
    parts = os.path.relpath(path, src)[:-3].split(os.sep)
    if parts[-1] in ("mod", "lib", "main"):
        parts = parts[:-1]
    return tuple(parts)


def cycles(root, crate, problems):
    src = os.path.join(crate, "src")
    files = {module_of(src, p): os.path.relpath(p, root) for p in rust_files(src)}
    edges = {}
    for mod, rel in files.items():
        text = without_tests(blank(open(os.path.join(root, rel), encoding="utf-8", errors="replace").read()))
        here = mod if rel.endswith(("mod.rs", "lib.rs", "main.rs")) else mod
        parent = here[:-1]
        targets = set()
        paths = [("crate", p) for p in re.findall(r"\bcrate::((?:\w+::)*\w+)", text)]
        paths += [("super", p) for p in re.findall(r"\bsuper::((?:\w+::)*\w+)", text)]
        for block in re.findall(r"\buse\s+crate::\{([^;]*)\}", text, flags=re.S):
            paths += [("crate", p) for p in re.findall(r"\w+(?:::\w+)*", block)]
        for base, p in paths:
            full = (() if base == "crate" else parent) + tuple(p.split("::"))
            for k in range(len(full), 0, -1):
                if full[:k] in files:
                    targets.add(files[full[:k]])
                    break
        targets.discard(rel)
        edges[rel] = targets

    def top(f):
        m = re.match(r"(.*?/src/)([^/]+?)(\.rs|/.*)?$", f)
        return m.group(1) + m.group(2) if m else f

    folded = {}
    for v, ws in edges.items():
        folded.setdefault(top(v), set()).update(top(w) for w in ws if top(w) != top(v) and not top(w).endswith(("/lib", "/main")))
    for graph in (edges, folded):
        # No cycle is allowed, the effect catalogue's included: its plug-ins depend on the
        # model, the model on neither (`common/src/setup.rs` applies the effects to a run).
        for comp in strongly_connected(graph):
            problems.append("module cycle: " + " <-> ".join(sorted(comp)))


def strongly_connected(graph):
    """Tarjan's strongly connected components of more than one node, iteratively."""
    index, low, on, stack, out, counter = {}, {}, set(), [], [], [0]
    for root in list(graph):
        if root in index:
            continue
        work = [(root, iter(sorted(graph.get(root, ()))))]
        index[root] = low[root] = counter[0]; counter[0] += 1
        stack.append(root); on.add(root)
        while work:
            v, it = work[-1]
            w = next(it, None)
            if w is not None:
                if w not in index:
                    index[w] = low[w] = counter[0]; counter[0] += 1
                    stack.append(w); on.add(w)
                    work.append((w, iter(sorted(graph.get(w, ())))))
                elif w in on:
                    low[v] = min(low[v], index[w])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[v])
            if low[v] == index[v]:
                comp = []
                while True:
                    w = stack.pop(); on.discard(w); comp.append(w)
                    if w == v:
                        break
                if len(comp) > 1:
                    out.append(comp)
    return out


def crate_deps(crate):
    """(package name, its `sepval-*` normal dependencies) from `crate`/Cargo.toml."""
    toml = open(os.path.join(crate, "Cargo.toml"), encoding="utf-8").read()
    name = re.search(r'^name\s*=\s*"([^"]+)"', toml, flags=re.M).group(1)
    deps = re.search(r"^\[dependencies\]\n(.*?)(^\[|\Z)", toml, flags=re.M | re.S)
    used = set(re.findall(r"^(sepval[\w-]*)\s*[.=]", deps.group(1), flags=re.M)) if deps else set()
    return name, used


def layers(root, crate, problems):
    name, used = crate_deps(crate)
    if name not in MAY_USE:
        problems.append(f"crate {name}: not in scripts/shape.py's MAY_USE (add it, and to ARCHITECTURE.md)")
        return
    for d in sorted(used - MAY_USE[name]):
        problems.append(f"crate {name} depends on {d}, which ARCHITECTURE.md does not allow")


def members(root):
    """{folder: (package name, its sepval dependencies)} of the workspace's members."""
    toml = open(os.path.join(root, "Cargo.toml"), encoding="utf-8").read()
    listed = re.search(r"^members\s*=\s*\[(.*?)\]", toml, flags=re.M | re.S).group(1)
    listed = re.sub(r"#[^\n]*", "", listed)
    return {f: crate_deps(os.path.join(root, f)) for f in re.findall(r'"([^"]+)"', listed)}


def documented(root, problems):
    """ARCHITECTURE.md's crates and dependencies against the workspace and MAY_USE."""
    doc = "ARCHITECTURE.md"
    text = open(os.path.join(root, doc), encoding="utf-8").read()
    block = re.search(r"^```crates\n(.*?)^```", text, flags=re.M | re.S)
    if not block:
        problems.append(f"{doc}: no ```crates block (the table of crates and their dependencies)")
        return
    found = members(root)
    by_name = {name: (folder, used) for folder, (name, used) in found.items()}
    table = {}
    for line in block.group(1).strip().split("\n"):
        m = re.fullmatch(r"([\w-]+) \(([\w/.-]+)\): (.*)", line.strip())
        if not m:
            problems.append(f"{doc}: crates table line `{line}`: expected `name (folder): a, b` or `: none`")
            continue
        name, folder, deps = m.groups()
        table[name] = set() if deps.strip() == "none" else {d.strip() for d in deps.split(",")}
        if folder not in found or found[folder][0] != name:
            problems.append(f"{doc}: crate {name} ({folder}) is not a workspace member in that folder")
            continue
        if table[name] != found[folder][1]:
            problems.append(f"{doc}: crate {name} depends on {sorted(found[folder][1])} in {folder}/Cargo.toml, the table says {sorted(table[name])}")
        if table[name] != MAY_USE.get(name):
            problems.append(f"{doc}: crate {name}'s dependencies differ from scripts/shape.py's MAY_USE")
    for name in sorted(set(by_name) - set(table)):
        problems.append(f"{doc}: workspace member {name} ({by_name[name][0]}) is missing from the crates table")
    for name in sorted(set(MAY_USE) - set(by_name)):
        problems.append(f"scripts/shape.py: MAY_USE names {name}, which is not a workspace member")
    for name in sorted(set(re.findall(r"\bsepval-[a-z]+\b(?![/\w-])", text)) - set(by_name)):
        problems.append(f"{doc}: names {name}, which is not a workspace member")
    for x, y in re.findall(r"\b(sepval[\w-]*)`?\)? depends on `?(sepval[\w-]*)", text):
        if x in by_name and y not in by_name[x][1]:
            problems.append(f"{doc}: says {x} depends on {y}, but {by_name[x][0]}/Cargo.toml does not")


def untested(crate, problems):
    toml = open(os.path.join(crate, "Cargo.toml"), encoding="utf-8").read()
    if not re.search(r"^test\s*=\s*false", toml, flags=re.M):
        return
    for path in rust_files(os.path.join(crate, "src")):
        if "#[test]" in open(path, encoding="utf-8", errors="replace").read():
            problems.append(f"{path}: has #[test], but its crate's Cargo.toml says test = false (the test would never run)")


def main():
    root = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..")
    root = os.path.abspath(root)
    problems = []
    for crate in sources(root):
        for path in rust_files(os.path.join(crate, "src")):
            sizes(root, path, open(path, encoding="utf-8", errors="replace").read(), problems)
        cycles(root, crate, problems)
        layers(root, crate, problems)
        untested(crate, problems)
    documented(root, problems)
    for p in problems:
        print(p)
    print(f"shape: {len(problems)} problem(s) (files <= {FILE_MAX} lines, functions <= {FN_MAX}, no module cycle, crates one way, ARCHITECTURE.md true to the crates, no test left unrun)")
    sys.exit(1 if problems else 0)


if __name__ == "__main__":
    main()
