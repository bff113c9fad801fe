#!/usr/bin/env bash
# Regenerates scenes/validation/cantilever_reference.json: CalculiX (ccx)
# reference solutions for the gravity-loaded clamped box cantilever used by
# the CPU-solver validation tests.  See README.md in this folder.
#
# Only needs bash, POSIX awk (mawk is fine), sed and ccx.  All ccx jobs run in
# a temporary directory that is removed on exit; the only file written in the
# repository is the JSON (path overridable with OUT_JSON=...).
#
# Environment knobs (defaults reproduce the committed JSON):
#   MESHES   mesh ladder "nx:ny:nz ..." (last one = reported reference)
#   ELTYPE   C3D20R (default) or C3D20
#   CASES    subset of "A B C-lin C-nl" to run (for checks; the JSON then
#            only holds those)
#   G_C      gravity magnitude of the large-deflection case C [m/s^2]
#   OUT_JSON output file
#   KEEP_WORK=1  keep the temp dir (path is printed) for inspection
set -eu

here=$(cd "$(dirname "$0")" && pwd)
OUT_JSON=${OUT_JSON:-$here/../cantilever_reference.json}
TEMPLATE=$here/cantilever.inp.in
MESHES=${MESHES:-"10:2:2 20:4:4 40:8:8"}
ELTYPE=${ELTYPE:-C3D20R}
CASES=${CASES:-"A B C-lin C-nl"}

# ---- problem definition (SI) -------------------------------------------
L=0.1; B=0.02; H=0.02            # x in [0,L], y in [-B/2,B/2], z in [-H/2,H/2]
E=1.0e6; NU=0.3; RHO=1000.0
G_A=9.81                          # cases A, B
# Case C: linear tip deflection ~ 0.30 L.  Case A (linear) gives a tip
# deflection of 3.762e-3 m = 0.0376 L on the 40x8x8 mesh, so 0.30 L needs
# g = 9.81 * 0.030 / 3.762e-3 = 78.2.  We take exactly 8 x 9.81 = 78.48, so
# that C-lin = 8 x A exactly (tip at 0.301 L).
G_C=${G_C:-78.48}
REL_TOL=0.003                     # required change between the last two meshes

NAME=make_cantilever_reference.sh WORK_PREFIX=phyxel-ccx
. "$here/ccx_setup.sh"

# ---- structured 20-node hex mesh (box_mesh.awk) ---------------------------
# Writes mesh.inp (ccx) and nodes.txt ("id I J K x y z twin") in directory $1.
gen_mesh() { # dir nx ny nz
    awk -v nx="$2" -v ny="$3" -v nz="$4" -v L="$L" -v B="$B" -v H="$H" \
        -v eltype="$ELTYPE" -v mesh="$1/mesh.inp" -v tab="$1/nodes.txt" \
        -f "$here/box_mesh.awk"
}

# ---- one ccx job ----------------------------------------------------------
# run_case dir g nlgeom(0|1)  -> writes job.inp, runs ccx, prints results line
run_case() {
    dir=$1; g=$2; nl=$3
    if [ "$nl" = 1 ]; then
        step='*STEP,NLGEOM,INC=1000'
        # automatic incrementation (no DIRECT): initial 0.05, period 1,
        # min 1e-6, max 0.1
        static='*STATIC\n0.05,1.,1.e-6,0.1'
    else
        step='*STEP'
        static='*STATIC'
    fi
    awk -v E="$E" -v NU="$NU" -v RHO="$RHO" -v G="$g" \
        -v step="$step" -v static="$static" '
        { gsub(/@E@/, E); gsub(/@NU@/, NU); gsub(/@RHO@/, RHO); gsub(/@G@/, G)
          gsub(/@GX@/, "0."); gsub(/@GY@/, "0."); gsub(/@GZ@/, "-1.")
          if ($0 == "@STEP_LINE@") $0 = step
          if ($0 == "@STATIC_BLOCK@") $0 = static
          print }' "$TEMPLATE" > "$dir/job.inp"
    grep -v '^\*\*' "$dir/job.inp" | grep -q '@[A-Z_]*@' && die "unfilled placeholder in $dir/job.inp"
    (cd "$dir" && nice ccx -i job > job.log 2>&1) || {
        tail -n 20 "$dir/job.log" >&2; die "ccx failed in $dir"; }
    grep -q '\*ERROR' "$dir/job.log" && { grep '\*ERROR' "$dir/job.log" >&2; die "ccx reported an error in $dir"; }
    grep -q 'Job finished' "$dir/job.log" || { tail -n 20 "$dir/job.log" >&2; die "ccx did not finish in $dir"; }
    # Parse the LAST displacement block of job.dat (= end of the step) and
    # reduce it with the node table.  Output:
    #   time uz_c ux_c uz_mean ux_mean maxu x_at_max y_at_max z_at_max ntip ninc
    awk -v NI="$NI" -v NJ="$NJ" -v NK="$NK" '
        FNR == NR { I[$1] = $2; J[$1] = $3; K[$1] = $4
                    X[$1] = $5; Y[$1] = $6; Z[$1] = $7; next }
        /displacements \(vx,vy,vz\)/ { blk++; t = $NF; delete ux; delete uy; delete uz; next }
        blk && NF == 4 && $1 ~ /^[0-9]+$/ { ux[$1] = $2; uy[$1] = $3; uz[$1] = $4 }
        END {
            if (!blk) { print "NO_OUTPUT"; exit 1 }
            sz = 0; sx = 0; nt = 0; mx = -1; cz = "nan"; cx = "nan"
            for (n in ux) {
                a = sqrt(ux[n]^2 + uy[n]^2 + uz[n]^2)
                if (a > mx) { mx = a; mn = n }
                if (I[n] == NI) {
                    nt++; sz += uz[n]; sx += ux[n]
                    if (J[n] == NJ / 2 && K[n] == NK / 2) { cz = uz[n]; cx = ux[n] }
                }
            }
            printf "%.7g %.7e %.7e %.7e %.7e %.7e %.6g %.6g %.6g %d %d\n", \
                t, cz, cx, sz / nt, sx / nt, mx, X[mn], Y[mn], Z[mn], nt, blk
        }' "$dir/nodes.txt" "$dir/job.dat"
}

# ---- run the ladder ---------------------------------------------------------
RES=$WORK/results.txt   # case mesh nx ny nz nodes elems <run_case output>
: > "$RES"
for m in $MESHES; do
    nx=${m%%:*}; r=${m#*:}; ny=${r%%:*}; nz=${r#*:}
    [ $((ny % 2)) = 0 ] && [ $((nz % 2)) = 0 ] || die "ny, nz must be even (tip centre must be a node): $m"
    NI=$((2 * nx)); NJ=$((2 * ny)); NK=$((2 * nz))
    for c in $CASES; do
        case $c in
            A)     g=$G_A; nl=0 ;;
            B)     g=$G_A; nl=1 ;;
            C-lin) g=$G_C; nl=0 ;;
            C-nl)  g=$G_C; nl=1 ;;
            *)     die "unknown case '$c' (known: A B C-lin C-nl)" ;;
        esac
        d=$WORK/${nx}x${ny}x${nz}_$c
        mkdir -p "$d"
        ne=$(gen_mesh "$d" "$nx" "$ny" "$nz")
        t0=$(date +%s)
        out=$(run_case "$d" "$g" "$nl") ||
            die "case $c mesh ${nx}x${ny}x${nz} failed (ccx error above, or no displacements in job.dat)"
        t1=$(date +%s)
        set -- $out
        awk -v t="$1" 'BEGIN { exit !(t > 0.999999 && t < 1.000001) }' ||
            die "case $c mesh ${nx}x${ny}x${nz}: step did not reach time 1 (last time $1)"
        echo "$c ${nx}x${ny}x${nz} $nx $ny $nz $ne $g $nl $out" >> "$RES"
        printf '%-6s %-8s nodes=%-6s tip uz=%s ux=%s  (%ss)\n' \
            "$c" "${nx}x${ny}x${nz}" "${ne%% *}" "$2" "$3" "$((t1 - t0))" >&2
        [ "${KEEP_WORK:-0}" = 1 ] || rm -rf "$d"
    done
done

# ---- JSON ------------------------------------------------------------------
awk -v L="$L" -v B="$B" -v H="$H" -v E="$E" -v NU="$NU" -v RHO="$RHO" \
    -v gA="$G_A" -v gC="$G_C" -v ver="$CCX_VERSION" -v date="$DATE" \
    -v eltype="$ELTYPE" -v tol="$REL_TOL" '
function geom(   y0, y1, z0, z1) {
    y0 = -B / 2; y1 = B / 2; z0 = -H / 2; z1 = H / 2
    return "{\"L\": " L ", \"b\": " B ", \"h\": " H ", \"x\": [0, " L "], \"y\": [" \
           y0 ", " y1 "], \"z\": [" z0 ", " z1 "]}"
}
function vals(r, ind) {
    return ind "\"tip_center_uz\": " f[r, 11] ",\n" \
           ind "\"tip_center_ux\": " f[r, 12] ",\n" \
           ind "\"tip_face_mean_uz\": " f[r, 13] ",\n" \
           ind "\"tip_face_mean_ux\": " f[r, 14] ",\n" \
           ind "\"max_abs_u\": " f[r, 15] ",\n" \
           ind "\"max_abs_u_at\": [" f[r, 16] ", " f[r, 17] ", " f[r, 18] "]"
}
function rel(a, b) { return (a - b) / b }
function absf(a) { return a < 0 ? -a : a }
# results.txt fields: 1 case 2 mesh 3 nx 4 ny 5 nz 6 nodes 7 elems 8 g 9 nlgeom
#   10 time 11 uz_c 12 ux_c 13 uz_mean 14 ux_mean 15 max|u| 16-18 its x,y,z
#   19 tip-face nodes 20 output blocks (increments)
{ nr++; for (i = 1; i <= NF; i++) f[nr, i] = $i
  if (!($1 in seen)) { seen[$1] = 1; order[++nc] = $1 }
  prev2[$1] = prev[$1]; prev[$1] = cur[$1]; cur[$1] = nr
}
END {
    A = B * H; I2 = B * H * H * H / 12; q = RHO * gA * A
    G = E / (2 * (1 + NU)); kap = 5 / 6
    eb = q * L^4 / (8 * E * I2); sh = q * L^2 / (2 * kap * G * A)
    printf "{\n"
    printf "  \"description\": \"CalculiX reference solutions: clamped box cantilever (clamp at x = 0) under gravity -z; static; tip = face x = L\",\n"
    printf "  \"generator\": \"scenes/validation/ccx/make_cantilever_reference.sh\",\n"
    printf "  \"solver\": {\"name\": \"CalculiX ccx\", \"version\": \"%s\"},\n", ver
    printf "  \"date\": \"%s\",\n", date
    printf "  \"units\": \"SI (m, kg, s, Pa)\",\n"
    printf "  \"element_type\": \"%s\",\n", eltype
    printf "  \"boundary\": \"u = 0 (x, y, z) on every node with x = 0\",\n"
    printf "  \"load\": \"body force rho*g per unit reference volume, fixed direction -z (*DLOAD GRAV)\",\n"
    printf "  \"material_model\": \"linear isotropic elastic; with nlgeom = true CalculiX applies it to Green-Lagrange strain / 2nd Piola-Kirchhoff stress (St Venant-Kirchhoff)\",\n"
    printf "  \"quantities\": {\n"
    printf "    \"tip_center_uz\": \"u_z at the node (L, 0, 0)\",\n"
    printf "    \"tip_center_ux\": \"u_x at the node (L, 0, 0)\",\n"
    printf "    \"tip_face_mean_uz\": \"arithmetic mean of u_z over all FE nodes (corner and mid-edge) on x = L (not area weighted)\",\n"
    printf "    \"tip_face_mean_ux\": \"arithmetic mean of u_x over all FE nodes on x = L\",\n"
    printf "    \"max_abs_u\": \"max over all nodes of |u|; max_abs_u_at = reference position of that node\"\n"
    printf "  },\n"
    printf "  \"convergence_tolerance\": %s,\n", tol
    printf "  \"cases\": {\n"
    for (c = 1; c <= nc; c++) {
        k = order[c]; r = cur[k]; p = prev[k]; pp = prev2[k]
        # Richardson estimate from the last three meshes (refinement ratio 2)
        rich = "null"; ord = "null"
        if (pp != "") {
            d1 = f[p, 11] - f[pp, 11]; d2 = f[r, 11] - f[p, 11]
            if (d2 != 0 && d1 / d2 > 1) {
                po = log(d1 / d2) / log(2)
                ord = sprintf("%.3g", po)
                rich = sprintf("%.7e", f[r, 11] + d2 / (2^po - 1))
            }
        }
        if (p == "") { ds = "null"; ok = "null" }
        else { d = rel(f[r, 11], f[p, 11]); ds = sprintf("%.3e", d)
               ok = absf(d) < tol ? "true" : "false" }
        printf "    \"%s\": {\n", k
        printf "      \"inputs\": {\"E\": %s, \"nu\": %s, \"rho\": %s, \"g\": [0, 0, %s], \"nlgeom\": %s, \"geometry\": %s},\n", \
            E, NU, RHO, -f[r, 8], (f[r, 9] == 1 ? "true" : "false"), geom()
        printf "      \"mesh\": {\"divisions\": [%d, %d, %d], \"element\": \"%s\", \"nodes\": %d, \"elements\": %d, \"tip_face_nodes\": %d},\n", \
            f[r, 3], f[r, 4], f[r, 5], eltype, f[r, 6], f[r, 7], f[r, 19]
        printf "      \"results\": {\n%s\n      },\n", vals(r, "        ")
        printf "      \"tip_center_uz_over_L\": %.6g,\n", f[r, 11] / L
        printf "      \"rel_change_tip_center_uz_last_two_meshes\": %s,\n", ds
        printf "      \"mesh_converged\": %s,\n", ok
        printf "      \"tip_center_uz_richardson\": %s,\n", rich
        printf "      \"observed_order\": %s\n", ord
        printf "    }%s\n", (c < nc ? "," : "")
    }
    printf "  },\n"
    printf "  \"convergence\": [\n"
    for (r = 1; r <= nr; r++) {
        printf "    {\"case\": \"%s\", \"mesh\": \"%s\", \"nodes\": %d, \"elements\": %d,\n", f[r, 1], f[r, 2], f[r, 6], f[r, 7]
        printf "     \"tip_center_uz\": %s, \"tip_center_ux\": %s, \"tip_face_mean_uz\": %s, \"tip_face_mean_ux\": %s, \"max_abs_u\": %s}%s\n", \
            f[r, 11], f[r, 12], f[r, 13], f[r, 14], f[r, 15], (r < nr ? "," : "")
    }
    printf "  ],\n"
    printf "  \"hand_values_case_A\": {\n"
    printf "    \"q\": %.6g, \"I\": %.6g, \"A\": %.6g, \"G\": %.6g, \"kappa\": %.6g,\n", q, I2, A, G, kap
    printf "    \"euler_bernoulli_tip_uz\": %.6e,\n", -eb
    printf "    \"timoshenko_shear_term\": %.6e,\n", -sh
    printf "    \"timoshenko_tip_uz\": %.6e\n", -(eb + sh)
    printf "  }\n"
    printf "}\n"
}' "$RES" > "$WORK/out.json"

mv "$WORK/out.json" "$OUT_JSON.tmp.$$" && mv "$OUT_JSON.tmp.$$" "$OUT_JSON"
echo "wrote $OUT_JSON" >&2

# Fail loudly if the ladder is not converged to REL_TOL.
bad=$(awk -v tol="$REL_TOL" '
    { v = $11; if ($1 in cur) prv[$1] = cur[$1]; cur[$1] = v }
    END { for (k in cur) { if (!(k in prv)) continue
          d = (cur[k] - prv[k]) / prv[k]; if (d < 0) d = -d
          if (d >= tol) printf "%s(%.2e) ", k, d } }' "$RES")
[ -z "$bad" ] || die "mesh ladder not converged to $REL_TOL for: $bad"
