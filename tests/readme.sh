#!/usr/bin/env bash
# Runs every command of README.md's ```sh blocks as written, in order, so
# that the README stays true (issue #62). tests/all.sh calls it; alone:
#   bash tests/readme.sh            (after `cargo build --release`)
#
# - The commands run in a scratch folder holding links to the repository's
#   tracked files (configs/, examples/, …), so their outputs (out/…,
#   out-solve/…) land there, never in the checkout; `target` links to the
#   build ($CARGO_TARGET_DIR or target/), which the README's `export PATH=…`
#   line puts on the PATH. `cargo …` lines run in the repository itself.
# - A ```toml block whose first line is `# NAME.toml: …` is written to
#   NAME.toml first (the README's own study).
# - `mpcontact run|solve|check CONFIG` on a grid finer than
#   README_MAX_POINTS cells (default 64; 0: as written) gets
#   `--set grid.points=N --set grid.spacing_um=S` appended: the config's own
#   domain on N cells, so the whole README runs in a few minutes on 2 cores.
# - A block after `<!-- not-run: REASON -->` (the line before its fence) is
#   skipped and listed with its reason; use it for what cannot run here.
# A failing command fails the test, named with its README line.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
readme=${README:-$root/README.md}
target=${CARGO_TARGET_DIR:-$root/target}
max_points=${README_MAX_POINTS:-64}
scratch=$(mktemp -d "${TMPDIR:-/tmp}/mpcontact-readme.XXXXXX")
trap 'rm -rf "$scratch"' EXIT

# The repository's tracked top-level entries, linked (not copied).
( cd "$root" && git ls-files 2>/dev/null | cut -d/ -f1 | sort -u ) > "$scratch/.entries" \
  || true
[ -s "$scratch/.entries" ] \
  || ls "$root" | grep -v -x -e target -e out -e out-solve > "$scratch/.entries"
while read -r entry; do
  [ "$entry" = target ] || ln -s "$root/$entry" "$scratch/$entry"
done < "$scratch/.entries"
rm "$scratch/.entries"
ln -s "$target" "$scratch/target"

# The README as one bash script: its sh blocks, each line preceded by its
# line number; named toml blocks as files; skipped blocks as comments.
python3 - "$readme" > "$scratch/.readme-commands.sh" <<'EOF'
import re, shlex, sys

lines = open(sys.argv[1], encoding="utf-8").read().split("\n")
out = []
skipped = []
blocks = 0
i = 0
while i < len(lines):
    fence = re.match(r"^```(\w*)\s*$", lines[i])
    if not fence:
        i += 1
        continue
    lang, start = fence.group(1), i
    j = i + 1
    while j < len(lines) and lines[j].strip() != "```":
        j += 1
    body = lines[start + 1 : j]
    for n, text in enumerate(body, start=start + 2):
        if text.lstrip().startswith("```"):
            sys.exit(f"README.md:{n}: a fence with text after it; the block opened at line {start + 1} is not closed")
    k = start - 1
    while k >= 0 and not lines[k].strip():
        k -= 1
    marker = re.match(r"^<!--\s*not-run:\s*(.*?)\s*-->\s*$", lines[k]) if k >= 0 else None
    if marker and not marker.group(1):
        sys.exit(f"README.md:{k + 1}: a not-run marker needs its reason")
    if lang == "toml" and body:
        name = re.match(r"^#\s*([\w.-]+\.toml):", body[0])
        if name:
            out.append(f"cat > {shlex.quote(name.group(1))} <<'README_TOML'")
            out.extend(body)
            out.append("README_TOML")
    elif lang == "sh":
        if marker:
            skipped.append(f"README.md:{start + 1}: {marker.group(1)}")
        else:
            blocks += 1
            continued = False
            for n, text in enumerate(body, start=start + 2):
                if not continued and text.strip() and not text.lstrip().startswith("#"):
                    out.append(f"readme_line={n}; readme_command={shlex.quote(text.strip())}")
                    out.append('echo "README.md:$readme_line [${SECONDS} s]: $readme_command" >&2')
                out.append(text)
                continued = text.rstrip().endswith("\\")
    i = j + 1
for s in skipped:
    out.append(f"echo {shlex.quote('not run: ' + s)} >&2")
out.append(f"echo 'README: {blocks} sh blocks run, {len(skipped)} not run' >&2")
print("\n".join(out))
EOF

# What the commands run in: the repository for cargo, a coarser grid for
# mpcontact (see the header), stop at the first failure naming its line.
cat > "$scratch/.readme-prelude.sh" <<EOF
set -eEo pipefail
readme_root=$(printf %q "$root")
readme_max_points=$max_points
EOF
cat >> "$scratch/.readme-prelude.sh" <<'EOF'
trap 'echo "README.md:$readme_line: failed: $readme_command" >&2' ERR
cargo() { (cd "$readme_root" && command cargo "$@"); }
readme_coarser() {
  # The --set that puts a config of more than readme_max_points cells on
  # that many cells of the same domain (nothing otherwise).
  case "${1:-}" in run|solve|check) ;; *) return 0 ;; esac
  [ "$readme_max_points" -gt 0 ] || return 0
  local a config=
  for a in "$@"; do
    case "$a" in *.toml) [ -f "$a" ] && { config=$a; break; } ;; esac
  done
  [ -n "$config" ] || return 0
  awk -v max="$readme_max_points" '
    /^\[/ { grid = ($0 ~ /^\[grid\]/) }
    grid && /^points[ \t]*=/ { sub(/#.*/, ""); split($0, v, "="); n = v[2] + 0 }
    grid && /^spacing_um[ \t]*=/ { sub(/#.*/, ""); split($0, v, "="); d = v[2] + 0 }
    END { if (n > max && d > 0) printf "--set grid.points=%d --set grid.spacing_um=%.10g\n", max, n * d / max }
  ' "$config"
}
mpcontact() {
  local extra
  extra=$(readme_coarser "$@")
  # shellcheck disable=SC2086 # two --set pairs, split on purpose
  command mpcontact "$@" $extra
}
EOF

cd "$scratch"
start=$(date +%s)
bash -c 'source .readme-prelude.sh; source .readme-commands.sh'
echo "README commands: $(( $(date +%s) - start )) s" >&2
