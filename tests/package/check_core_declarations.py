#!/usr/bin/env python3
"""Every function a core public header declares is defined by splatfx::core.

A core-only consumer (find_package(splatfx COMPONENTS core)) may include every
core header; a function declared there but defined in another library
(splatfx::io, splatfx::gl, ...) compiles and then fails to link. This check
reads the declarations from clang's AST of each core header, keeps those
without a body (not defaulted, deleted, pure or implicit, not templates) and
looks each mangled name up among the symbols libsplatfx_core.a defines.

usage: check_core_declarations.py CLANGXX NM LIBCORE INCLUDE_DIR HEADER... [-- EXTRA_CLANG_FLAGS...]
(HEADER relative to INCLUDE_DIR, e.g. splatfx/grid.hpp; all go into one translation unit.)
Exit code 0 when every declaration is defined, 1 (listing them) otherwise.
"""
import json
import os
import subprocess
import sys
import tempfile

FUNCTION_KINDS = {"FunctionDecl", "CXXMethodDecl", "CXXConstructorDecl", "CXXDestructorDecl", "CXXConversionDecl"}
TEMPLATE_KINDS = {"FunctionTemplateDecl", "ClassTemplateDecl", "ClassTemplatePartialSpecializationDecl"}


def declarations(clangxx, include_dir, headers, extra):
    """(mangled name, readable name, file:line, has definition) for every function in namespace splatfx."""
    with tempfile.NamedTemporaryFile("w", suffix=".cpp", delete=False) as src:
        src.write("".join('#include "%s"\n' % h for h in headers))
    try:
        out = subprocess.run(
            [clangxx, "-std=c++20", "-fsyntax-only", "-I", include_dir, *extra, "-Xclang", "-ast-dump=json", "-Xclang",
             "-ast-dump-filter=splatfx", src.name],
            check=True, capture_output=True, text=True).stdout
    finally:
        os.unlink(src.name)
    # The filtered dump is a sequence of JSON objects, one per matching top-level declaration.
    decoder = json.JSONDecoder()
    roots, pos = [], 0
    while True:
        while pos < len(out) and out[pos] not in "{[":
            pos += 1
        if pos >= len(out):
            break
        node, pos = decoder.raw_decode(out, pos)
        roots.append(node)

    found = []
    state = {"file": ""}  # clang writes a location's file only where it changes, in document order

    def see(loc):
        if not isinstance(loc, dict):
            return ""
        for key in ("spellingLoc", "expansionLoc"):
            if key in loc:
                see(loc[key])
        if "file" in loc:
            state["file"] = loc["file"]
        return state["file"]

    def walk(node, in_template):
        file = see(node.get("loc"))
        rng = node.get("range", {})
        see(rng.get("begin"))
        see(rng.get("end"))
        kind = node.get("kind")
        if kind in FUNCTION_KINDS and not in_template and not node.get("isImplicit") and "mangledName" in node:
            inner = node.get("inner", [])
            defined = (any(c.get("kind") == "CompoundStmt" for c in inner) or node.get("explicitlyDefaulted") is not None or
                       node.get("explicitlyDeleted") or node.get("pure") or node.get("isThisDeclarationADefinition"))
            line = node.get("loc", {}).get("line", "?")
            found.append((node["mangledName"], node.get("name", "?"), "%s:%s" % (file, line), bool(defined)))
        for child in node.get("inner", []):
            walk(child, in_template or kind in TEMPLATE_KINDS)

    for root in roots:
        walk(root, False)
    return found


def main(argv):
    if "--" in argv:
        cut = argv.index("--")
        args, extra = argv[1:cut], argv[cut + 1:]
    else:
        args, extra = argv[1:], []
    clangxx, nm, lib, include_dir, headers = args[0], args[1], args[2], args[3], args[4:]
    defined_symbols = set(subprocess.run([nm, "--defined-only", "-g", "-P", lib], check=True, capture_output=True,
                                         text=True).stdout.split("\n"))
    defined_symbols = {line.split(" ")[0] for line in defined_symbols if line}

    declared = {}
    for mangled, name, where, has_body in declarations(clangxx, include_dir, headers, extra):
        if not where.startswith(include_dir):
            continue  # a declaration from outside the SDK's headers (the standard library, glm)
        entry = declared.setdefault(mangled, {"name": name, "where": where, "body": False})
        entry["body"] = entry["body"] or has_body

    missing = sorted((e["where"], m) for m, e in declared.items() if not e["body"] and m not in defined_symbols)
    checked = sum(1 for e in declared.values() if not e["body"])
    if not missing:
        print("core headers: %d declared functions, all defined in %s" % (checked, os.path.basename(lib)))
        return 0
    demangled = subprocess.run(["c++filt"], input="\n".join(m for _, m in missing), capture_output=True, text=True).stdout.split("\n")
    print("core headers declare %d function(s) that splatfx::core does not define (a core-only consumer would fail to link);"
          " move each to an io or gl header:" % len(missing))
    for (where, mangled), readable in zip(missing, demangled):
        print("  %s: %s" % (os.path.relpath(where, include_dir), readable or mangled))
    return 1


if __name__ == "__main__":
    sys.exit(main(sys.argv))
