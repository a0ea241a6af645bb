#!/usr/bin/env bash
# Builds the dh3 container image with podman on a Debian 12 machine, from
# Debian's packages alone (no image registry needed):
#
#   deploy/container/build-image.sh [--tag NAME] [--remake-base] [--base-only]
#                                   [--prebuilt STAGE_DIR]
#
# 1. installs podman and what it needs here (runc, uidmap, slirp4netns,
#    fuse-overlayfs), mmdebstrap, and docker-compose (for the Compose file);
# 2. makes the base images the Dockerfile names, debian:bookworm and
#    debian:bookworm-slim, with mmdebstrap from the Debian archive apt already
#    uses on this machine (read from its apt sources now), unless podman has
#    them already (--remake-base makes them again);
# 3. builds deploy/container/Dockerfile as NAME (default dh3:latest) in
#    Docker's image format: the OCI format has no HEALTHCHECK and podman would
#    drop it. --base-only stops after step 2: the package test
#    (tests/package) builds its systemd image on the same base.
#    --prebuilt STAGE_DIR takes the build stage's result from STAGE_DIR, as
#    deploy/container/build-in-image.sh made it on this machine, instead of
#    compiling in the build stage (the image test: the test command has
#    compiled everything already).
#
# Podman runs with deploy/container/containers.conf (CONTAINERS_CONF; set it
# yourself to use another). Runs as root (re-runs itself through sudo).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd -P)
src=$(cd "$here/../.." && pwd -P)
tag=dh3:latest
remake_base=0
base_only=0
prebuilt=
while (($#)); do
  case $1 in
    --tag) tag=$2; shift 2 ;;
    --remake-base) remake_base=1; shift ;;
    --base-only) base_only=1; shift ;;
    --prebuilt) prebuilt=${2:?--prebuilt needs a directory}; shift 2 ;;
    -h | --help) sed -n '2,27s/^# \{0,1\}//p' "$0"; exit 0 ;;
    *) echo "build-image: unknown argument $1" >&2; exit 2 ;;
  esac
done
if [[ $(id -u) -ne 0 ]]; then
  exec sudo --preserve-env=CONTAINERS_CONF,JOBS "$0" "$@"
fi
export CONTAINERS_CONF=${CONTAINERS_CONF:-$here/containers.conf}
say() { echo "build-image: $*"; }

# 1. The engine.
engine_pkgs=(podman runc uidmap slirp4netns fuse-overlayfs mmdebstrap docker-compose)
missing=()
for p in "${engine_pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' || missing+=("$p")
done
if ((${#missing[@]})); then
  say "installing ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

# 2. The base images, from this machine's Debian archive. bookworm_sources
# prints the archive lines for bookworm (the release, its updates and security) from the apt
# sources, one-line style, keeping signed-by.
bookworm_sources() {
  local f
  {
    if [[ -f /etc/apt/sources.list ]]; then cat /etc/apt/sources.list; fi
    for f in /etc/apt/sources.list.d/*.list; do if [[ -f $f ]]; then cat "$f"; fi; done
  } | awk '
    /^[ \t]*deb[ \t]/ {
      opts = ""; i = 2
      if ($2 ~ /^\[/) { while ($i !~ /\]$/) { opts = opts " " $i; i++ } opts = opts " " $i; i++ }
      uri = $i; suite = $(i + 1); comps = ""
      for (j = i + 2; j <= NF && $j !~ /^#/; j++) comps = comps " " $j
      if (suite ~ /^bookworm(-updates|-security)?$/) {
        gsub(/^ +/, "", opts); print "deb " (opts == "" ? "" : opts " ") uri " " suite comps
      }
    }'
  for f in /etc/apt/sources.list.d/*.sources; do
    [[ -f $f ]] || continue
    # deb822: blank lines end a stanza; fields may not be continued here.
    awk '
      function flush(   n, m, u, k, uris, suites) {
        if (types ~ /(^| )deb( |$)/ && enabled != "no") {
          n = split(uris_f, uris, " "); m = split(suites_f, suites, " ")
          for (u = 1; u <= n; u++)
            for (k = 1; k <= m; k++)
              if (suites[k] ~ /^bookworm(-updates|-security)?$/)
                print "deb " (signed == "" ? "" : "[signed-by=" signed "] ") uris[u] " " suites[k] " " comps
        }
        types = uris_f = suites_f = comps = signed = enabled = ""
      }
      /^[ \t]*#/ { next }
      /^[ \t]*$/ { flush(); next }
      {
        key = tolower($1); sub(/:$/, "", key); $1 = ""; sub(/^ +/, "")
        if (key == "types") types = $0
        else if (key == "uris") uris_f = $0
        else if (key == "suites") suites_f = $0
        else if (key == "components") comps = $0
        else if (key == "signed-by") signed = $0
        else if (key == "enabled") enabled = $0
      }
      END { flush() }' "$f"
  done
}

# One root for both names: minbase, merged /usr, and, as Debian's official
# slim image has it, no manual pages, documentation or translations
# (copyrights stay). The build stage does not miss them either, but Java's
# postinst (fastddsgen needs a JRE) links its manual page into
# /usr/share/man/man1 and fails if the folder is not there: keep it.
base_tags=(debian:bookworm debian:bookworm-slim)
missing_tags=()
for base_tag in "${base_tags[@]}"; do
  if ((!remake_base)) && podman image exists "$base_tag"; then
    say "$base_tag: present ($(podman image inspect --format '{{.Id}}' "$base_tag" | cut -c1-12))"
  else
    missing_tags+=("$base_tag")
  fi
done
if ((${#missing_tags[@]})); then
  mapfile -t sources < <(bookworm_sources)
  ((${#sources[@]})) || {
    echo "build-image: no Debian bookworm archive in /etc/apt/sources.list{,.d}" >&2
    exit 1
  }
  work=$(mktemp -d)
  trap 'rm -rf "$work"' EXIT
  # This machine's settings for reaching its archive go with its archive
  # lines: a proxy, or a snapshot archive whose Release files have expired
  # (Check-Valid-Until "false") that plain apt would refuse. mmdebstrap keeps
  # them in the image's /etc/apt/apt.conf.d, so builds on these bases reach
  # the archive too. apt-config prints the merged configuration one line each.
  acquire_opts=()
  if apt-config dump | grep -E '^Acquire::(Check-Valid-Until|Check-Date|Max-ValidTime|https?::|ftp::)' \
      >"$work/acquire.conf"; then
    acquire_opts=(--aptopt="$work/acquire.conf")
    say "with this machine's apt Acquire:: settings ($(wc -l <"$work/acquire.conf") line(s))"
  fi
  say "mmdebstrap --variant=minbase bookworm from ${#sources[@]} archive line(s) of this machine's apt sources"
  # merged-usr: the /usr merge as debootstrap does it (symlinks and
  # usr-is-merged); otherwise apt satisfies init-system-helpers with the
  # usrmerge package and its 47 MB of Perl.
  mmdebstrap --quiet --variant=minbase --hook-dir=/usr/share/mmdebstrap/hooks/merged-usr \
    --dpkgopt='path-exclude=/usr/share/man/*' --dpkgopt='path-exclude=/usr/share/info/*' \
    --dpkgopt='path-exclude=/usr/share/doc/*' --dpkgopt='path-include=/usr/share/doc/*/copyright' \
    --dpkgopt='path-exclude=/usr/share/locale/*' --dpkgopt='path-exclude=/usr/share/lintian/*' \
    --customize-hook='mkdir -p "$1/usr/share/man/man1"' "${acquire_opts[@]}" \
    bookworm "$work/rootfs.tar" "${sources[@]}"
  for base_tag in "${missing_tags[@]}"; do
    podman import --quiet --change 'CMD ["/bin/bash"]' "$work/rootfs.tar" "$base_tag" >/dev/null
    say "$base_tag: imported ($(podman image inspect --format '{{.Size}}' "$base_tag") bytes)"
  done
  rm -rf "$work"
fi

((base_only)) && exit 0

# 3. The image. --network=host: the build's apt reaches the archive as this
# machine does.
say "podman build --format docker -t $tag"
start=$(date +%s)
# --prebuilt: a build context named after the build stage replaces that stage
# (podman and BuildKit alike); the runtime stage copies its /stage/.
build_opts=()
if [[ -n $prebuilt ]]; then
  [[ -d $prebuilt/usr/local/bin ]] || { echo "build-image: $prebuilt is not a staged tree" >&2; exit 2; }
  context=$(mktemp -d)
  trap 'rm -rf "$context"' EXIT
  cp -a "$prebuilt" "$context/stage"
  build_opts=(--build-context "build=$context")
  say "the build stage from $prebuilt"
fi
podman build --format docker --network=host --ignorefile "$here/Dockerfile.dockerignore" \
  "${build_opts[@]}" -f "$here/Dockerfile" -t "$tag" "$src"
say "built $tag in $(($(date +%s) - start)) s: $(podman image inspect --format '{{.Size}}' "$tag") bytes"
