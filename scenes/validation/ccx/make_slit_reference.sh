#!/usr/bin/env bash
# Regenerates scenes/validation/cantilever_slit_reference.json: CalculiX (ccx) reference
# solutions for the gravity-loaded clamped box cantilever with a half-depth slit (duplicated
# nodes) and, on the same meshes, without it. See README.md in this folder.
#
# Needs bash, POSIX awk, sed and ccx. The ccx jobs run in a temporary directory removed on
# exit; the only file written in the repository is the JSON (OUT_JSON=... overrides it).
#
# Environment knobs (defaults reproduce the committed JSON):
#   MESHES   mesh ladder "nx:ny:nz ..." (last one = reported reference); nx a multiple of 10
#            (the slit plane x = 0.03 on an element face), ny and nz even
#   ELTYPE   C3D20R (default) or C3D20
#   NLGEOM   1: geometrically nonlinear steps (default 0: linear, as case A)
#   OUT_JSON output file
#   KEEP_WORK=1  keep the temp dir (path is printed)
set -eu

here=$(cd "$(dirname "$0")" && pwd)
OUT_JSON=${OUT_JSON:-$here/../cantilever_slit_reference.json}
TEMPLATE=$here/cantilever.inp.in
MESHES=${MESHES:-"20:4:4 40:8:8 60:12:12 80:16:16"}
ELTYPE=${ELTYPE:-C3D20R}
NLGEOM=${NLGEOM:-0}

# ---- problem definition (SI): the beam of make_cantilever_reference.sh, case A ------------
L=0.1; B=0.02; H=0.02
E=1.0e6; NU=0.3; RHO=1000.0; G=9.81
XC=0.03                           # the slit's plane
ZT=0                              # its front: the slit runs from z = H/2 down to z = ZT

NAME=make_slit_reference.sh WORK_PREFIX=phyxel-ccx-slit
. "$here/ccx_setup.sh"

if [ "$NLGEOM" = 1 ]; then
    STEP='*STEP,NLGEOM,INC=1000'; STATIC='*STATIC\n0.05,1.,1.e-6,0.1'
else
    STEP='*STEP'; STATIC='*STATIC'
fi

# One job: mesh (with the slit when $5 = 1), ccx, and the reduced results line
#   uz_tip_centre uz_tip_face_mean mouth_opening(u_x twin - u_x original at (XC, 0, H/2))
run_job() { # dir nx ny nz slit
    dir=$1; nx=$2; ny=$3; nz=$4
    ci=-1; ck=0
    if [ "$5" = 1 ]; then
        ci=$(awk -v n="$nx" -v x="$XC" -v l="$L" 'BEGIN { c = n * x / l; r = int(c + 0.5)
            if (c - r > 1e-9 || r - c > 1e-9) exit 1; print r }') ||
            die "mesh $nx:$ny:$nz: the slit plane x = $XC is not an element face"
        ck=$(awk -v n="$nz" -v z="$ZT" -v h="$H" 'BEGIN { print int(n * (z + h / 2) / h + 0.5) }')
    fi
    awk -v nx="$nx" -v ny="$ny" -v nz="$nz" -v L="$L" -v B="$B" -v H="$H" \
        -v eltype="$ELTYPE" -v mesh="$dir/mesh.inp" -v tab="$dir/nodes.txt" \
        -v crack_i="$ci" -v crack_k="$ck" -f "$here/box_mesh.awk" > "$dir/size.txt"
    awk -v E="$E" -v NU="$NU" -v RHO="$RHO" -v G="$G" -v step="$STEP" -v static="$STATIC" '
        { gsub(/@E@/, E); gsub(/@NU@/, NU); gsub(/@RHO@/, RHO); gsub(/@G@/, G)
          gsub(/@GX@/, "0."); gsub(/@GY@/, "0."); gsub(/@GZ@/, "-1.")
          if ($0 == "@STEP_LINE@") $0 = step
          if ($0 == "@STATIC_BLOCK@") $0 = static
          print }' "$TEMPLATE" > "$dir/job.inp"
    (cd "$dir" && nice ccx -i job > job.log 2>&1) || { tail -n 20 "$dir/job.log" >&2; die "ccx failed in $dir"; }
    grep -q '\*ERROR' "$dir/job.log" && { grep '\*ERROR' "$dir/job.log" >&2; die "ccx reported an error in $dir"; }
    grep -q 'Job finished' "$dir/job.log" || { tail -n 20 "$dir/job.log" >&2; die "ccx did not finish in $dir"; }
    awk -v NI=$((2 * nx)) -v NJ=$((2 * ny)) -v NK=$((2 * nz)) -v CI=$((2 * ci)) '
        FNR == NR { I[$1] = $2; J[$1] = $3; K[$1] = $4; T[$1] = $8; next }
        /displacements \(vx,vy,vz\)/ { blk++; t = $NF; delete ux; delete uz; next }
        blk && NF == 4 && $1 ~ /^[0-9]+$/ { ux[$1] = $2; uz[$1] = $4 }
        END {
            if (!blk || t < 0.999999) { print "NO_OUTPUT"; exit 1 }
            sz = 0; nt = 0; cz = "nan"; mouth = 0
            for (n in uz) {
                if (I[n] == NI) {
                    nt++; sz += uz[n]
                    if (J[n] == NJ / 2 && K[n] == NK / 2) cz = uz[n]
                }
                if (CI >= 0 && I[n] == CI && J[n] == NJ / 2 && K[n] == NK)
                    mouth += (T[n] ? 1 : -1) * ux[n]
            }
            printf "%.7e %.7e %.7e\n", cz, sz / nt, mouth
        }' "$dir/nodes.txt" "$dir/job.dat"
}

RES=$WORK/results.txt   # mesh nodes elements slit(0|1) uz_centre uz_mean mouth
: > "$RES"
for m in $MESHES; do
    nx=${m%%:*}; r=${m#*:}; ny=${r%%:*}; nz=${r#*:}
    [ $((ny % 2)) = 0 ] && [ $((nz % 2)) = 0 ] || die "ny, nz must be even: $m"
    for slit in 0 1; do
        d=$WORK/${nx}x${ny}x${nz}_$slit
        mkdir -p "$d"
        t0=$(date +%s)
        out=$(run_job "$d" "$nx" "$ny" "$nz" "$slit") || die "mesh $m slit $slit failed"
        t1=$(date +%s)
        echo "${nx}x${ny}x${nz} $(cat "$d/size.txt") $slit $out" >> "$RES"
        printf '%-9s slit=%s %s  (%ss)\n' "${nx}x${ny}x${nz}" "$slit" "$out" "$((t1 - t0))" >&2
        [ "${KEEP_WORK:-0}" = 1 ] || rm -rf "$d"
    done
done

awk -v ver="$CCX_VERSION" -v date="$DATE" -v eltype="$ELTYPE" -v nl="$NLGEOM" \
    -v L="$L" -v B="$B" -v H="$H" -v E="$E" -v NU="$NU" -v RHO="$RHO" -v G="$G" \
    -v XC="$XC" -v ZT="$ZT" '
{ nr++; for (i = 1; i <= NF; i++) f[nr, i] = $i }
function row(r) {
    return sprintf("{\"mesh\": \"%s\", \"nodes\": %d, \"elements\": %d, \"slit\": %s, \"tip_center_uz\": %s, \"tip_face_mean_uz\": %s, \"mouth_opening\": %s}", \
        f[r, 1], f[r, 2], f[r, 3], (f[r, 4] ? "true" : "false"), f[r, 5], f[r, 6], f[r, 7])
}
END {
    whole = nr - 1; slit = nr; prev = nr - 2
    printf "{\n"
    printf "  \"description\": \"CalculiX reference: the clamped box cantilever of cantilever_reference.json (case A) with a slit across its whole width in the plane x = %s from the top face z = %s down to z = %s (duplicated nodes), and without it on the same meshes; static, gravity -z\",\n", XC, H / 2, ZT
    printf "  \"generator\": \"scenes/validation/ccx/make_slit_reference.sh\",\n"
    printf "  \"solver\": {\"name\": \"CalculiX ccx\", \"version\": \"%s\"},\n", ver
    printf "  \"date\": \"%s\",\n", date
    printf "  \"units\": \"SI (m, kg, s, Pa)\",\n"
    printf "  \"element_type\": \"%s\",\n", eltype
    printf "  \"nlgeom\": %s,\n", (nl == 1 ? "true" : "false")
    printf "  \"inputs\": {\"E\": %s, \"nu\": %s, \"rho\": %s, \"g\": [0, 0, -%s], \"L\": %s, \"b\": %s, \"h\": %s, \"slit\": {\"x\": %s, \"z_from\": %s, \"z_to\": %s}},\n", E, NU, RHO, G, L, B, H, XC, ZT, H / 2
    printf "  \"quantities\": {\"tip_center_uz\": \"u_z at the node (L, 0, 0)\", \"tip_face_mean_uz\": \"mean u_z over the FE nodes on x = L\", \"mouth_opening\": \"u_x of the +x face minus u_x of the -x face at (x_slit, 0, h/2)\"},\n"
    printf "  \"results\": {\"slit\": %s, \"whole\": %s, \"slit_over_whole\": %.6f,\n", f[slit, 5], f[whole, 5], f[slit, 5] / f[whole, 5]
    printf "              \"rel_change_slit_last_two_meshes\": %.3e},\n", (prev > 0 ? (f[slit, 5] - f[prev, 5]) / f[prev, 5] : 0)
    printf "  \"convergence\": [\n"
    for (r = 1; r <= nr; r++) printf "    %s%s\n", row(r), (r < nr ? "," : "")
    printf "  ]\n}\n"
}' "$RES" > "$WORK/out.json"
mv "$WORK/out.json" "$OUT_JSON.tmp.$$" && mv "$OUT_JSON.tmp.$$" "$OUT_JSON"
echo "wrote $OUT_JSON" >&2
