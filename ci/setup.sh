#!/usr/bin/env bash
# Installs what building and testing ocular needs on Debian/Ubuntu, and prepares the shaderc
# archive that build.rs links. Idempotent: safe to run again; it only does what is missing.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
say() { printf 'ci/setup.sh: %s\n' "$*"; }

sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then
    command -v sudo >/dev/null || { say "not root and no sudo: install the packages below by hand"; exit 1; }
    sudo_cmd=(sudo)
fi

# Vulkan loader + headers, Mesa's CPU driver (lavapipe), the validation layer, the shader
# compiler libraries and tools.
packages=(
    libvulkan1 libvulkan-dev mesa-vulkan-drivers vulkan-tools vulkan-validationlayers
    libshaderc-dev glslang-dev spirv-tools glslc
    pkg-config binutils ca-certificates
    python3 python3-venv python3-pip
    chromium
)
# The viewer's browser test (tests/viewer/) runs on Node: Debian's, unless one is installed.
command -v node >/dev/null || packages+=(nodejs)
command -v npm >/dev/null || packages+=(npm)
missing=()
for p in "${packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
    say "installing with apt: ${missing[*]}"
    "${sudo_cmd[@]}" apt-get update -qq
    DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
else
    say "system packages already installed"
fi

if ! command -v cargo >/dev/null; then
    say "cargo not found: install Rust (1.87 or newer) with rustup, then run this again"
    exit 1
fi

# Debian's libshaderc_combined.a holds only shaderc's own objects; glslang and SPIRV-Tools
# live in separate archives. Merge them into one archive that shaderc-sys can link statically,
# in a folder outside target/ so that `cargo clean` keeps it. .cargo/config.toml points
# SHADERC_LIB_DIR here. Without it shaderc-sys would try a 10+ minute source build.
libdir=/usr/lib/$(gcc -dumpmachine 2>/dev/null || echo x86_64-linux-gnu)
out="$here/.deps/shaderc"
archive="$out/libshaderc_combined.a"
parts=(shaderc_combined glslang MachineIndependent GenericCodeGen OSDependent OGLCompiler HLSL
       SPIRV glslang-default-resource-limits SPIRV-Tools-opt SPIRV-Tools)
stamp="$out/inputs.txt"
want=""
for p in "${parts[@]}"; do
    f="$libdir/lib$p.a"
    [ -f "$f" ] || { say "missing $f (package libshaderc-dev / glslang-dev / spirv-tools)"; exit 1; }
    want+="$f $(stat -c %s "$f")"$'\n'
done
if [ -f "$archive" ] && [ -f "$stamp" ] && [ "$(cat "$stamp")" == "$want" ]; then
    say "shaderc archive up to date: $archive"
else
    say "merging Debian's shaderc, glslang and SPIRV-Tools archives into $archive"
    mkdir -p "$out"
    script="CREATE $archive.tmp"$'\n'
    for p in "${parts[@]}"; do script+="ADDLIB $libdir/lib$p.a"$'\n'; done
    script+=$'SAVE\nEND\n'
    rm -f "$archive.tmp"
    printf '%s' "$script" | ar -M
    mv "$archive.tmp" "$archive"
    printf '%s' "$want" > "$stamp"
    # shaderc-sys caches the library location: make it look again.
    (cd "$here" && cargo clean -p shaderc-sys >/dev/null 2>&1) || true
fi

# playwright-core for the viewer's browser test, at the version package-lock.json pins; it
# drives Debian's chromium (its own browser download is never used).
viewer="$here/tests/viewer"
want=$(node -p "require('$viewer/package-lock.json').packages['node_modules/playwright-core'].version")
have=$(node -p "require('$viewer/node_modules/playwright-core/package.json').version" 2>/dev/null || true)
if [ "$want" == "$have" ]; then
    say "playwright-core $have already installed"
else
    say "installing playwright-core (npm ci in tests/viewer)"
    (cd "$viewer" && PLAYWRIGHT_SKIP_BROWSER_DOWNLOAD=1 npm ci --no-audit --no-fund --loglevel=error >/dev/null)
fi

say "done. Vulkan devices visible to the loader:"
vulkaninfo --summary 2>/dev/null | grep -E 'deviceName|deviceType' | sed 's/^/    /' || say "vulkaninfo found no device"
