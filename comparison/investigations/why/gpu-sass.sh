#!/usr/bin/env bash
# What each driver made of the teapot's compute tracer, as machine code. Each
# app runs once with NVIDIA's shader disk cache in a folder of its own
# (__GL_SHADER_DISK_CACHE_PATH, which the Vulkan driver reads too). A cache
# file holds zstd frames; a frame that holds an "NVuc" container holds the
# machine code, as the section the container's table lists first (its size at
# byte 0x44 of the container, its offset at 0x48; Vulkan's section is as long
# as the "Binary Size" that --dump-shaders reports). That section goes through
# `nvdisasm -b SM90`, and the instructions are counted by opcode. The default
# tree (4-wide) at each app's default shape (Vulkan 8x16, OpenGL 8x4) and
# Vulkan at 8x4 too. zstd comes from PATH or from ZSTD (a zstd binary carried
# along); nvdisasm from PATH or /usr/local/cuda/bin. About 10 s.
# OUT_DIR/FORM.sass (FORM: vk, gl, vk-8x4), OUT_DIR/FORM.counts (count,
# opcode), OUT_DIR/summary.txt (each form's sections and instruction totals).
# Usage: comparison/investigations/why/gpu-sass.sh BIN_DIR OUT_DIR
set -u
bin=$1 out=$2
mkdir -p "$out"
export PATH=$PATH:/usr/local/cuda/bin
zstd=${ZSTD:-zstd}
: > "$out/summary.txt"
for form in vk gl vk-8x4; do
    app=${form%%-*}
    cache=$out/cache-$form
    rm -rf "$cache" && mkdir -p "$cache"
    extra=()
    [ "$form" = vk-8x4 ] && extra=(--workgroup 8x4)
    __GL_SHADER_DISK_CACHE=1 __GL_SHADER_DISK_CACHE_PATH=$cache __GL_SHADER_DISK_CACHE_SKIP_CLEANUP=1 \
        timeout 120 "$bin/twinray-$app" --headless --scene teapot --size 64x64 --path compute "${extra[@]}" \
        > /dev/null 2>> "$out/errors.log"
    python3 - "$cache" "$out/$form" "$zstd" >> "$out/summary.txt" <<'PY'
import os, struct, subprocess, sys
cache, stem, zstd = sys.argv[1:4]
found = 0
for root, _, files in os.walk(cache):
    for name in sorted(files):
        data = open(os.path.join(root, name), "rb").read()
        blobs = [data]
        i = data.find(b"\x28\xb5\x2f\xfd")
        while i >= 0:
            p = subprocess.run([zstd, "-d", "-c"], input=data[i:], capture_output=True)
            blobs.append(p.stdout)
            i = data.find(b"\x28\xb5\x2f\xfd", i + 4)
        for blob in blobs:
            o = blob.find(b"NVuc")
            if o < 0:
                continue
            size, offset = struct.unpack_from("<II", blob, o + 0x44)
            code = blob[o + offset:o + offset + size]
            if found == 0 and len(code) == size and size % 16 == 0:
                open(stem + ".code", "wb").write(code)
            print(f"{os.path.basename(stem)}: NVuc in {name}, code {size} bytes at {offset}")
            found += 1
print(f"{os.path.basename(stem)}: {found} code sections")
PY
    if [ -s "$out/$form.code" ]; then
        nvdisasm -b SM90 "$out/$form.code" > "$out/$form.sass" 2>> "$out/errors.log"
        grep -oE '^\s+/\*[0-9a-f]{4,}\*/\s+(@!?U?P[0-9T] )?[A-Z][A-Z0-9_]*' "$out/$form.sass" | awk '{print $NF}' |
            sort | uniq -c | sort -rn > "$out/$form.counts"
        echo "$form: $(awk '{t += $1} END {print t + 0}' "$out/$form.counts") instructions" >> "$out/summary.txt"
    fi
    rm -rf "$cache"
done
cat "$out/summary.txt"
