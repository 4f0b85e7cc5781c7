#!/usr/bin/env bash
# Downloads chosen subjects of the CMU Graphics Lab Motion Capture Database in their native
# ASF/AMC form into a cache outside the repository. Run with --help for the details.
#
# How the site is organised (checked against the site's pages and links, 2024):
#   skeleton  http://mocap.cs.cmu.edu/subjects/NN/NN.asf
#   motion    http://mocap.cs.cmu.edu/subjects/NN/NN_TT.amc
#   trials    the subject's page http://mocap.cs.cmu.edu/search.php?subjectnumber=N links every
#             NN_TT.amc; when it cannot be read, trials 01, 02, ... are tried until the first
#             one that does not exist (so a gap in the numbering ends the list early).
# NN is the subject number padded to at least two digits (06, 86, 124), TT the trial padded to
# two. The site is plain http: its https certificate is not valid.
set -euo pipefail

# FETCH_CMU_SITE points the script at a local copy or a test server instead of the real site.
readonly SITE="${FETCH_CMU_SITE:-http://mocap.cs.cmu.edu}"
HOST=${SITE#*://}
readonly HOST=${HOST%%/*}

usage() {
  cat <<EOF
Usage: tools/fetch_cmu.sh [--out DIR] SUBJECT[_TRIAL]...

Downloads subjects of the CMU Graphics Lab Motion Capture Database ($HOST) in their
native ASF/AMC form: the subject's skeleton NN.asf and its motions NN_TT.amc.

Arguments:
  SUBJECT          every trial of a subject, e.g. 86 (the trial list comes from the
                   subject's page on the site and is kept as DIR/NN/trials.txt)
  SUBJECT_TRIAL    one trial, e.g. 86_01 (numbers are zero-padded: 2_3 means 02_03)

Options:
  --out DIR        cache folder; files go to DIR/NN/ (default: \${XDG_CACHE_HOME:-~/.cache}/mocap/cmu,
                   now $(default_out))
  -h, --help       show this text

Files already in the cache are not downloaded again, so an interrupted run can simply be
repeated; downloads are written under a temporary name and renamed when complete.
Uses curl, or wget when curl is missing.

Exit status: 0 every requested file is in the cache; 1 a subject or trial does not exist or a
download failed; 2 bad usage; 3 $HOST cannot be reached (offline?).

The data is free for research and commercial use but may not be resold; publications should
acknowledge: "The data used in this project was obtained from mocap.cs.cmu.edu. The database
was created with funding from NSF EIA-0196217." The site asks not to be crawled: fetch the
subjects you need (the whole database is one zip linked from $SITE/faqs.php).
Read the files with motion::read_asf_amc(); lengths are in ASF units (x 0.056444 = metres).
EOF
}

default_out() { echo "${XDG_CACHE_HOME:-$HOME/.cache}/mocap/cmu"; }

die() {
  local status=$1
  shift
  echo "fetch_cmu: $*" >&2
  exit "$status"
}

# ---- Downloading ----

if command -v curl >/dev/null 2>&1; then
  readonly TOOL=curl
elif command -v wget >/dev/null 2>&1; then
  readonly TOOL=wget
else
  die 1 "neither curl nor wget is installed"
fi

# download URL FILE: 0 when done, 1 when the file does not exist (HTTP 404 or 410), 2 when the
# site cannot be reached or answers with another error (no network, a proxy refusing, 5xx).
# A short description of a failure is left in $WORK/error.
download() {
  local url=$1 out=$2 status=0 code
  if [[ $TOOL == curl ]]; then
    code=$(curl --silent --show-error --location --connect-timeout 20 --max-time 1800 \
      --write-out '%{http_code}' --output "$out" "$url" 2>"$WORK/error") || status=$?
  else
    wget --server-response --timeout=20 --tries=2 --output-document="$out" "$url" \
      2>"$WORK/log" || status=$?
    code=$(sed -nE 's/^ *HTTP\/[0-9.]+ ([0-9]{3}).*/\1/p' "$WORK/log" | tail -n 1)
    grep -vE '^ |^--|^$|^Length|^Saving|^HTTP request' "$WORK/log" | tail -n 2 >"$WORK/error" || true
  fi
  case ${code:-000} in
    200) ((status == 0)) && return 0 ;;
    404 | 410) return 1 ;;
    000) ;;  # no answer at all: the tool's own message says why
    *) echo "HTTP $code for $url" >"$WORK/error" ;;
  esac
  return 2
}

network_error() {
  local detail
  detail=$(tr '\n' ' ' <"$WORK/error" | sed 's/ *$//')
  die 3 "cannot reach $HOST: offline? (${detail:-$TOOL failed}); nothing more was downloaded"
}

# fetch_file URL DEST: downloads into DEST unless it is there. Returns 1 (quietly) when the file
# does not exist, 2 (with a message) when the server sent something that is not ASF/AMC.
fetch_file() {
  local url=$1 dest=$2 status=0
  if [[ -s $dest ]]; then
    present=$((present + 1))
    return 0
  fi
  download "$url" "$dest.part" || status=$?
  if ((status == 2)); then
    rm -f "$dest.part"
    network_error
  fi
  if ((status == 1)); then
    rm -f "$dest.part"
    return 1
  fi
  # An error page served with status 200 would otherwise sit in the cache as a motion file.
  if [[ ! -s $dest.part ]] || head -c 2048 "$dest.part" | LC_ALL=C grep -q '^[[:space:]]*<'; then
    rm -f "$dest.part"
    echo "fetch_cmu: $url: the server sent an empty file or a web page, not ASF/AMC" >&2
    return 2
  fi
  mv -f "$dest.part" "$dest"
  fetched=$((fetched + 1))
  echo "fetched ${dest#"$OUT"/} ($(wc -c <"$dest" | tr -d ' ') bytes)"
}

# ---- Trials of a subject ----

# Prints the subject's trial numbers (two digits, one a line) from its page on the site.
trials_from_page() {
  local subject=$1 number=$((10#$1)) status=0
  download "$SITE/search.php?subjectnumber=$number" "$WORK/page" || status=$?
  if ((status == 2)); then network_error; fi
  if ((status == 1)); then return 0; fi
  { LC_ALL=C grep -oE "subjects/0*$number/0*${number}_[0-9]+\.amc" "$WORK/page" || true; } |
    sed -E 's/.*_([0-9]+)\.amc$/\1/' | while read -r t; do printf '%02d\n' $((10#$t)); done |
    sort -u
}

# Fetches trials 01, 02, ... until the first that does not exist (when the page gave no list).
fetch_trials_by_probing() {
  local subject=$1 trial=1 tt
  while ((trial <= 99)); do
    tt=$(printf '%02d' "$trial")
    fetch_file "$SITE/subjects/$subject/${subject}_$tt.amc" "$OUT/$subject/${subject}_$tt.amc" ||
      break
    echo "$tt" >>"$WORK/probed"
    trial=$((trial + 1))
  done
  if ((trial == 1)); then
    echo "fetch_cmu: subject $subject: no trial found (does the subject exist?)" >&2
    return 1
  fi
  mv -f "$WORK/probed" "$OUT/$subject/trials.txt"
}

fetch_subject() {
  local subject=$1 tt failed=0
  local list="$OUT/$subject/trials.txt"
  if [[ ! -s $list ]]; then
    trials_from_page "$subject" >"$WORK/trials"
    if [[ ! -s $WORK/trials ]]; then
      echo "fetch_cmu: subject $subject: no trial list on its page; trying trials 01, 02, ..." >&2
      fetch_trials_by_probing "$subject"
      return
    fi
    mv -f "$WORK/trials" "$list"
  fi
  while read -r tt; do
    [[ -n $tt ]] || continue
    fetch_trial "$subject" "$tt" || failed=1
  done <"$list"
  return "$failed"
}

fetch_trial() {
  local subject=$1 tt=$2 status=0
  fetch_file "$SITE/subjects/$subject/${subject}_$tt.amc" "$OUT/$subject/${subject}_$tt.amc" ||
    status=$?
  if ((status == 1)); then echo "fetch_cmu: trial ${subject}_$tt does not exist on $HOST" >&2; fi
  return "$status"
}

# ---- Main ----

OUT=$(default_out)
targets=()
while (($# > 0)); do
  case $1 in
    -h | --help)
      usage
      exit 0
      ;;
    --out)
      (($# >= 2)) || die 2 "--out needs a folder (see --help)"
      OUT=$2
      shift 2
      ;;
    --out=*)
      OUT=${1#--out=}
      shift
      ;;
    --)
      shift
      targets+=("$@")
      break
      ;;
    -*) die 2 "unknown option '$1' (see --help)" ;;
    *)
      targets+=("$1")
      shift
      ;;
  esac
done
((${#targets[@]} > 0)) || die 2 "name at least one SUBJECT or SUBJECT_TRIAL, e.g. 86 or 86_01 (see --help)"
[[ -n $OUT ]] || die 2 "--out needs a folder"

# Check every argument before downloading anything.
for target in "${targets[@]}"; do
  [[ $target =~ ^[0-9]{1,3}(_[0-9]{1,3})?$ ]] ||
    die 2 "'$target' is not SUBJECT or SUBJECT_TRIAL (e.g. 86 or 86_01)"
  ((10#${target%%_*} > 0)) || die 2 "'$target': subjects are numbered from 1"
done

mkdir -p "$OUT" || die 1 "cannot create $OUT"
OUT=$(cd "$OUT" && pwd)
if git -C "$OUT" rev-parse --is-inside-work-tree >/dev/null 2>&1; then
  echo "fetch_cmu: warning: $OUT is inside a git work tree; never commit the downloaded data" >&2
fi
WORK=$(mktemp -d "${TMPDIR:-/tmp}/fetch_cmu.XXXXXX")
trap 'rm -rf "$WORK"; rm -f "$OUT"/*/*.part' EXIT

fetched=0
present=0
failed=0
for target in "${targets[@]}"; do
  subject=$(printf '%02d' $((10#${target%%_*})))
  mkdir -p "$OUT/$subject"
  status=0
  fetch_file "$SITE/subjects/$subject/$subject.asf" "$OUT/$subject/$subject.asf" || status=$?
  if ((status != 0)); then
    if ((status == 1)); then
      echo "fetch_cmu: subject $subject has no skeleton $subject.asf on $HOST (does it exist?)" >&2
    fi
    failed=1
    continue
  fi
  if [[ $target == *_* ]]; then
    fetch_trial "$subject" "$(printf '%02d' $((10#${target#*_})))" || failed=1
  else
    fetch_subject "$subject" || failed=1
  fi
done

echo "fetch_cmu: $fetched file(s) downloaded, $present already in the cache: $OUT"
exit "$failed"
