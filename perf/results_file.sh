# Sourced by the perf/ scripts that append rows to perf/results/: the machine's CPU model and the
# results file named after it.
#
#   source perf/results_file.sh
#   cpu_model                      # "AMD EPYC"
#   results_file "$repo" -joint    # <repo>/perf/results/amd-epyc-joint.csv

cpu_model() {
  local cpu
  cpu=$(awk -F': *' '/^model name/ { print $2; exit }' /proc/cpuinfo)
  echo "${cpu:-$(uname -m)}"
}

# results_file REPO [SUFFIX]: the CSV of this machine kind (lower case, (r)/(tm) dropped, runs of
# other characters as one dash; the host name when nothing is left).
results_file() {
  local slug
  slug=$(cpu_model | tr 'A-Z' 'a-z' | sed -e 's/([a-z]*)//g' -e 's/[^a-z0-9]\+/-/g' -e 's/^-//' -e 's/-$//')
  echo "$1/perf/results/${slug:-$(hostname)}${2:-}.csv"
}
