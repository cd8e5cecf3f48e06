#!/usr/bin/env bash
# What `make install` created under its destination, so that `make uninstall` removes exactly
# that: the files it put there and the folders it made, never a folder that was there before
# (an empty PREFIX/include or PREFIX/share/man/man1 belongs to the system, not to swim).
#
#   install_manifest.sh begin  SNAPSHOT   every path under $SWIM_INSTALL_DEST now, into SNAPSHOT
#   install_manifest.sh record SNAPSHOT   what is there now and was not in SNAPSHOT, merged into
#                                          the manifest (itself listed)
#   install_manifest.sh prune             the manifest's folders that are empty removed, deepest
#                                          first; the manifest too once every file it lists is gone
#   install_manifest.sh uninstall         every file and link the manifest lists removed, then prune
#
# The destination comes through the environment ($SWIM_INSTALL_DEST, an absolute path that may
# hold spaces and quotes). The manifest is DEST/share/swim/install-manifest: one path a line,
# relative to DEST ("." is DEST itself), so a moved tree keeps its manifest. Every install rule
# takes a snapshot before it (an order-only prerequisite) and records after it, so a line added
# to any install rule is covered without being named here.
set -euo pipefail
dest="${SWIM_INSTALL_DEST:?SWIM_INSTALL_DEST is not set}"
case "$dest" in /*) ;; *) echo "install_manifest.sh: '$dest' is not an absolute path" >&2; exit 2 ;; esac
manifest="$dest/share/swim/install-manifest"
rel="share/swim/install-manifest"

# every path under DEST, relative to it, sorted (nothing when DEST does not exist)
listing() {
    [ -e "$dest" ] || return 0
    ( cd "$dest" && find . -xdev -print | sed -e 's#^\./##' | LC_ALL=C sort )
}

prune() {
    [ -f "$manifest" ] || return 0
    # the manifest goes when every other file it lists is gone
    local left
    left=$(cd "$dest" && while IFS= read -r p; do
        if [ "$p" != "$rel" ] && { [ -L "$p" ] || { [ -e "$p" ] && [ ! -d "$p" ]; }; }; then echo "$p"; fi
    done <"$manifest")
    local dirs
    dirs=$(cd "$dest" && while IFS= read -r p; do
        if [ -d "$p" ] && [ ! -L "$p" ]; then echo "$p"; fi
    done <"$manifest" | LC_ALL=C sort -r)
    if [ -z "$left" ]; then rm -f "$manifest"; fi
    # deepest first (a reverse sort puts a/b before a); "." (DEST itself) last of all
    ( cd "$dest" && while IFS= read -r d; do
        if [ -n "$d" ] && [ "$d" != "." ]; then rmdir "$d" 2>/dev/null || true; fi
    done <<<"$dirs" )
    if [ -z "$left" ] && grep -qx '\.' <<<"$dirs"; then rmdir "$dest" 2>/dev/null || true; fi
    return 0
}

case "${1:-}" in
begin)
    # snapshots of make runs that are over (an install rule run alone keeps its own) go first:
    # their names end in the make's process id
    for f in "${2%.*}".*; do
        if [ -f "$f" ] && ! kill -0 "${f##*.}" 2>/dev/null; then rm -f "$f"; fi
    done
    listing >"$2"
    ;;
record)
    mkdir -p "$dest/share/swim"
    new=$(LC_ALL=C comm -13 "$2" <(listing))
    { if [ -f "$manifest" ]; then cat "$manifest"; fi; printf '%s\n' "$new" "$rel"; } \
        | grep -v '^$' | LC_ALL=C sort -u >"$manifest.tmp"
    mv -f "$manifest.tmp" "$manifest"
    ;;
prune)
    prune
    ;;
uninstall)
    [ -f "$manifest" ] || exit 0
    ( cd "$dest" && while IFS= read -r p; do
        if [ "$p" != "$rel" ] && { [ -L "$p" ] || { [ -e "$p" ] && [ ! -d "$p" ]; }; }; then rm -f "$p"; fi
    done <"$manifest" )
    prune
    ;;
*)
    echo "usage: $0 begin SNAPSHOT | record SNAPSHOT | prune | uninstall" >&2
    exit 2
    ;;
esac
