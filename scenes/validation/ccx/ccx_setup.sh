# Shared prologue of the ccx reference scripts, sourced after they set NAME (for messages),
# TEMPLATE, ELTYPE and WORK_PREFIX: die(), the checks, CCX_VERSION, DATE, the work directory
# WORK (removed on exit unless KEEP_WORK=1) and single-threaded ccx.
die() { echo "$NAME: error: $*" >&2; exit 1; }

command -v ccx >/dev/null 2>&1 || die "CalculiX 'ccx' not found in PATH - install calculix-ccx (Debian/Ubuntu: apt-get install calculix-ccx)"
[ -r "$TEMPLATE" ] || die "template $TEMPLATE missing"
case $ELTYPE in C3D20R|C3D20) ;; *) die "ELTYPE must be C3D20R or C3D20" ;; esac

CCX_VERSION=$(ccx -v 2>&1 | awk '/Version/ { print $NF; exit }')
[ -n "$CCX_VERSION" ] || CCX_VERSION=unknown
DATE=$(date -u +%Y-%m-%d)

WORK=$(mktemp -d "${TMPDIR:-/tmp}/$WORK_PREFIX.XXXXXX")
if [ "${KEEP_WORK:-0}" = 1 ]; then
    echo "work dir kept: $WORK" >&2
else
    trap 'rm -rf "$WORK"' EXIT
fi
trap 'exit 130' INT TERM

# Keep the runs light on shared machines.
export OMP_NUM_THREADS=${OMP_NUM_THREADS:-1}
export CCX_NPROC_EQUATION_SOLVER=${CCX_NPROC_EQUATION_SOLVER:-1}
