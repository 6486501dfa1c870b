#!/usr/bin/env bash
# The book's CI recipes (docs/src/ci-recipes.md) run here, from the page itself:
#   - each recipe's GitHub Actions job and GitLab CI job (the ```yaml blocks whose
#     first line is "# recipe: NAME, GitHub Actions ..." or "..., GitLab CI ...") are
#     read: the GitHub job's `run:` steps, less those under `sudo` (the machine's
#     setup), must be the GitLab job's `script:`, command for command (its
#     `before_script:` is the setup: apt-get, the clone); a recipe without both, or
#     without a command, is an error;
#   - the commands run in a scratch directory (target/ci-recipes) with this
#     repository as hiperface/ and the example project as the user's:
#       c-firmware     firmware-tests/ = examples/cmake-firmware (and the encoder
#                      it compiles, examples/c/tiny_encoder.c)
#       python-master  tests/ = examples/python-master
#       hardware-rig   encoder.toml = `hiperface export-profile SRS50`,
#                      HIPERFACE_PORT=sim (the reference simulator, not /dev/ttyUSB0),
#                      the baseline made first by the page's baseline command
#   - then each gate is shown to fail: the encoder with its checksum slip (ctest
#     fails), HX-M with a wrong checksum (pytest fails), and a device that regressed
#     against its baseline (the independent slave HX-1 on a pseudo-terminal, the
#     baseline its conformant run, then the run with a defect: compare exits 1).
# Needs what the recipes install (cargo-c, cmake, pkg-config, python3 with venv) and
# python3 to read the page. For the rig, CARGO_INSTALL_ROOT is the scratch directory,
# so that its `cargo install --path` does not touch ~/.cargo/bin (cargo-c, which the
# firmware's job installs, is the one already installed: .ci/run installs it).
#   scripts/ci-recipes.sh [RECIPE...]     (default: every recipe on the page)
set -euo pipefail
cd "$(dirname "$0")/.."
repo=$PWD
page=docs/src/ci-recipes.md
work=target/ci-recipes
rm -rf "$work"
mkdir -p "$work"
work=$(cd "$work" && pwd)

# The commands of each recipe, read from the page: $work/NAME.commands (one a line)
# and, for a baseline block, $work/NAME.baseline.
python3 - "$page" "$work" <<'PY'
import re, sys
page, out = sys.argv[1], sys.argv[2]
text = open(page).read()
blocks = re.findall(r"^```(yaml|sh)\n(.*?)^```", text, re.S | re.M)
recipes = {}
for lang, body in blocks:
    lines = body.splitlines()
    m = re.match(r"# recipe: ([a-z-]+), (GitHub Actions|GitLab CI|baseline)\b", lines[0]) if lines else None
    if not m:
        continue
    name, kind = m.groups()
    if kind == "baseline":
        commands = [l for l in lines[1:] if l.strip() and not l.startswith("#")]
    elif kind == "GitHub Actions":
        commands = []
        for i, l in enumerate(lines):
            r = re.match(r"^(\s*)(?:- )?run: (.*)$", l)
            if not r:
                continue
            if r.group(2).strip() in ("|", ">"):
                sys.exit(f"{page}: {name}: a multi-line run: step; keep one command per step")
            commands.append(r.group(2))
        commands = [c for c in commands if not c.startswith("sudo ")]
    else:
        commands, in_script = [], False
        for l in lines:
            key = re.match(r"^  ([a-z_]+):", l)
            if key:
                in_script = key.group(1) == "script"
                continue
            item = re.match(r"^    - (.*)$", l)
            if in_script and item:
                commands.append(item.group(1))
    if not commands:
        sys.exit(f"{page}: the {kind} block of {name} has no command")
    key = (name, kind)
    if key in recipes:
        sys.exit(f"{page}: two {kind} blocks for {name}")
    recipes[key] = commands
names = sorted({n for n, _ in recipes})
if not names:
    sys.exit(f"{page}: no recipe")
for name in names:
    gh, gl = recipes.get((name, "GitHub Actions")), recipes.get((name, "GitLab CI"))
    if gh is None or gl is None:
        sys.exit(f"{page}: {name} lacks its {'GitHub Actions' if gh is None else 'GitLab CI'} job")
    if gh != gl:
        sys.exit(f"{page}: {name}: the GitHub job runs\n  " + "\n  ".join(gh)
                 + "\nbut the GitLab job\n  " + "\n  ".join(gl))
    open(f"{out}/{name}.commands", "w").write("\n".join(gl) + "\n")
    if (name, "baseline") in recipes:
        open(f"{out}/{name}.baseline", "w").write("\n".join(recipes[(name, "baseline")]) + "\n")
    print(f"{name}: {len(gl)} commands, the same in both jobs")
PY

# Runs each command of FILE in the current directory, as the CI's shell would; with
# `expect-fail`, the last one must fail (the others pass).
run_commands() { # run_commands FILE [expect-fail]
    local n total=0 last
    total=$(wc -l < "$1")
    n=0
    while IFS= read -r cmd; do
        n=$((n + 1))
        echo "\$ $cmd"
        if [ "${2:-}" = expect-fail ] && [ "$n" -eq "$total" ]; then
            if bash -eo pipefail -c "$cmd"; then echo "the gate passed where it must fail: $cmd"; return 1; fi
            echo "(failed, as it must)"
        else
            bash -eo pipefail -c "$cmd"
        fi
    done < "$1"
}

# Lays out a recipe's scratch directory: this repository as hiperface/.
project() { # project NAME
    mkdir -p "$work/$1"
    ln -sfn "$repo" "$work/$1/hiperface"
    cd "$work/$1"
}

recipes=("$@")
if [ ${#recipes[@]} -eq 0 ]; then
    for f in "$work"/*.commands; do recipes+=("$(basename "$f" .commands)"); done
fi
for recipe in "${recipes[@]}"; do
    [ -f "$work/$recipe.commands" ] || { echo "no recipe $recipe in $page"; exit 2; }
    start=$(date +%s)
    case "$recipe" in
    c-firmware)
        echo "== c-firmware: the GitHub/GitLab job's commands"
        project c-firmware
        cp -r "$repo/examples/cmake-firmware" firmware-tests
        mkdir -p c && cp "$repo/examples/c/tiny_encoder.c" c/
        run_commands "$work/$recipe.commands"
        grep -q "<testcase" build/junit.xml || { echo "ctest wrote no JUnit test cases"; exit 1; }
        echo "-- the encoder with its checksum slip (expected: ctest fails)"
        cmake -S firmware-tests -B build -DTINY_ENCODER_DEFECT=ON > /dev/null
        cmake --build build > /dev/null
        tail -1 "$work/$recipe.commands" > "$work/$recipe.gate"
        run_commands "$work/$recipe.gate" expect-fail > "$work/$recipe.defect.txt" 2>&1 \
            || { cat "$work/$recipe.defect.txt"; exit 1; }
        grep -E "FAIL \[000:2.3.3\]|tests passed|Failed" "$work/$recipe.defect.txt" | sort -u
        grep -q "FAIL \[000:2.3.3\]" "$work/$recipe.defect.txt" || { echo "not failed on the checksum clause"; exit 1; }
        ;;
    python-master)
        echo "== python-master: the GitHub/GitLab job's commands"
        project python-master
        cp -r "$repo/examples/python-master" tests
        export HIPERFACE_SRC=$repo
        run_commands "$work/$recipe.commands"
        grep -q 'tests="1"' junit.xml || { echo "pytest's JUnit file does not count one test"; exit 1; }
        python3 - master-report/junit.xml <<'PY'
import sys, xml.etree.ElementTree as ET
s = ET.parse(sys.argv[1]).getroot()
assert int(s.get("tests")) > 0 and int(s.get("failures")) == 0, (s.get("tests"), s.get("failures"))
print(f"master-report/junit.xml: {s.get('tests')} scenarios, {s.get('failures')} failures")
PY
        echo "-- HX-M with a wrong checksum (expected: pytest fails, on 000:2.3/master)"
        tail -1 "$work/$recipe.commands" > "$work/$recipe.gate"
        DRIVE_DEFECT=wrong-checksum run_commands "$work/$recipe.gate" expect-fail > "$work/$recipe.defect.txt" 2>&1 \
            || { cat "$work/$recipe.defect.txt"; exit 1; }
        grep -E "^=+ .*(failed|passed)" "$work/$recipe.defect.txt" | tail -1
        grep -q "000:2.3/master" "$work/$recipe.defect.txt" || { echo "not failed on 000:2.3/master"; exit 1; }
        unset HIPERFACE_SRC
        ;;
    hardware-rig)
        echo "== hardware-rig: the baseline, then the GitHub/GitLab job's commands (HIPERFACE_PORT=sim)"
        project hardware-rig
        # `cargo install --path` into the scratch directory, not ~/.cargo/bin.
        export CARGO_INSTALL_ROOT=$work/cargo
        export PATH=$CARGO_INSTALL_ROOT/bin:$PATH
        [ -f "$work/$recipe.baseline" ] || { echo "$page has no baseline command for the rig"; exit 1; }
        # The job installs the command first; the baseline is made with it too.
        head -1 "$work/$recipe.commands" > "$work/$recipe.install"
        grep -q "^cargo install" "$work/$recipe.install" || { echo "the rig's first command does not install hiperface"; exit 1; }
        run_commands "$work/$recipe.install"
        tail -n +2 "$work/$recipe.commands" > "$work/$recipe.run"
        cargo run -q --release -p hiperface-conformance --manifest-path "$repo/Cargo.toml" -- export-profile SRS50 > encoder.toml
        HIPERFACE_PORT=sim run_commands "$work/$recipe.baseline"
        HIPERFACE_PORT=sim run_commands "$work/$recipe.run"
        grep -q "<testcase" report/junit.xml && grep -q "<testcase" comparison/comparison-junit.xml \
            || { echo "a JUnit file without test cases"; exit 1; }
        echo "-- a device that regressed: HX-1, baseline conformant, then with a defect (expected: compare exits 1)"
        hx1() { # hx1 [--defect NAME]: starts HX-1 on a pseudo-terminal; its path in $port
            rm -f "$work/hx1.path"
            # In a session of its own (the pipe's `sleep` included), ended as a group.
            setsid bash -c 'sleep 600 | python3 "$@"' _ "$repo/conformance/tests/independent/hx1_slave.py" --pty "$@" \
                > "$work/hx1.path" &
            hx1_pid=$!
            for _ in $(seq 50); do [ -s "$work/hx1.path" ] && break; sleep 0.1; done
            sleep 0.3
            port=$(head -1 "$work/hx1.path")
        }
        rm -rf baseline report comparison
        cp "$repo/conformance/tests/independent/hx1.toml" encoder.toml
        hx1
        HIPERFACE_PORT=$port run_commands "$work/$recipe.baseline" > "$work/hx1-baseline.txt" 2>&1 \
            || { kill -- -"$hx1_pid"; cat "$work/hx1-baseline.txt"; exit 1; }
        kill -- -"$hx1_pid" 2>/dev/null || true
        tail -1 "$work/hx1-baseline.txt"
        hx1 --defect wrong-error-code
        HIPERFACE_PORT=$port run_commands "$work/$recipe.run" expect-fail > "$work/hx1-regressed.txt" 2>&1 \
            || { kill -- -"$hx1_pid"; cat "$work/hx1-regressed.txt"; exit 1; }
        kill -- -"$hx1_pid" 2>/dev/null || true
        grep -iE "regress" "$work/hx1-regressed.txt" | head -5
        grep -qi "regress" "$work/hx1-regressed.txt" || { echo "compare did not name a regression"; exit 1; }
        unset CARGO_INSTALL_ROOT
        ;;
    *)
        echo "a recipe this script does not know how to lay out: $recipe"; exit 2 ;;
    esac
    cd "$repo"
    echo "$recipe: passed, and its gate fails where it must ($(( $(date +%s) - start )) s)"
done
echo "CI recipes passed"
