#!/usr/bin/env bash
# The 16-core run (issue 29), from the bundle only (tools/manycore/bundle.sh copies this script into it as
# run-all.sh): step scaling (at the top thread count also with the loop board off, with each loop's own grain,
# and pile2k with the broad-phase update's old flat bar), union-find, the step's stages and loops, contended
# broad-phase queries, the demo and, where the bundle has Jolt's harness, Jolt's step beside Cairn's, with
# CSVs, a scaling chart and a Markdown summary written to RESULTS, the summary printed last. Needs
# bash, awk, grep, sed and /proc (no packages); pins nothing and changes no machine setting.
# Usage: bash run-all.sh RESULTS     (in the bundle; from the repository: CAIRN_BUNDLE=<bundle> bash
#        tools/manycore/run.sh RESULTS). CAIRN_RUN_THREADS / CAIRN_RUN_QUERY_THREADS override the sweeps,
#        CAIRN_RUN_DEMO_FRAMES the demo's frames per mode (0: no demo), CAIRN_RUN_JOLT_UNTIL the seconds
#        after which the Jolt harness is skipped.
set -uo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
bundle=${CAIRN_BUNDLE:-$here}
[ -x "$bundle/run" ] || { echo "run.sh: no launcher at $bundle/run (make the bundle first)" >&2; exit 2; }
[ $# -ge 1 ] || { echo "usage: run-all.sh RESULTS" >&2; exit 2; }
out=$1
mkdir -p "$out" || exit 2
out=$(cd "$out" && pwd)
cores=$(nproc)
model=$(grep -m1 "model name" /proc/cpuinfo | cut -d: -f2- | sed 's/^ *//')

# The sweeps: up to 16 threads and 15 query threads (one core for the mover), no more than the cores
sweep() { # <list> <max>
    echo "$1" | tr ',' '\n' | awk -v max="$2" '$1 >= 1 && $1 <= max' | paste -sd, -
}
threads=${CAIRN_RUN_THREADS:-$(sweep 1,2,4,8,16 "$cores")}
queryThreads=${CAIRN_RUN_QUERY_THREADS:-$(sweep 1,2,4,8,15 "$((cores > 1 ? cores - 1 : 1))")}
demoFrames=${CAIRN_RUN_DEMO_FRAMES:-1200}
started=$(date -u +%Y-%m-%dT%H:%M:%SZ)
{
    echo "date: $started"
    echo "nproc: $cores"
    echo "cpu: $model"
    echo "kernel: $(uname -r)"
    echo "threads: $threads; query threads: $queryThreads"
} >"$out/machine.txt"
echo "run.sh: $cores cores ($model); threads $threads; query threads $queryThreads"

# Google Benchmark's JSON (one key a line) to CSV rows: name, label, then the given counters
json_rows() { # <file> <counters...>
    local file=$1
    shift
    awk -v keys="$*" '
        BEGIN { n = split(keys, want, " ") }
        /"name":/ { if (name != "") emit(); name = $0; sub(/.*"name": "/, "", name); sub(/",?$/, "", name); label = ""; delete value }
        /"label":/ { label = $0; sub(/.*"label": "/, "", label); sub(/",?$/, "", label) }
        /^ *"[a-z_]+": [-0-9.e+]+,?$/ { key = $1; gsub(/[":]/, "", key); v = $2; sub(/,$/, "", v); value[key] = v }
        END { if (name != "") emit() }
        function emit(   i, row) {
            row = name "," "\"" label "\""
            for (i = 1; i <= n; ++i) row = row "," ((want[i] in value) ? value[want[i]] + 0 : "")
            print row
            name = ""
        }' "$file"
}

# Table rows comparing two files of alternated cairn-bench-step runs (--repetitions 1 each), for each scene
# that both hold: the medians of the runs' mean and serial ms in the first and the second, and their ratio
compare_runs() { # <first> <second>
    awk '
        function median(list,   n, v, i, j, t) { n = split(list, v, " ")
            for (i = 2; i <= n; ++i) for (j = i; j > 1 && v[j - 1] + 0 > v[j] + 0; --j) { t = v[j]; v[j] = v[j - 1]; v[j - 1] = t }
            return n == 0 ? 0 : (n % 2 ? v[(n + 1) / 2] : (v[n / 2] + v[n / 2 + 1]) / 2) }
        FNR == 1 { file++ }
        / rep 0: / { scenes[file, $1] = 1
            for (i = 1; i <= NF; ++i) { if ($i == "mean") means[file, $1] = means[file, $1] " " $(i + 1)
                if ($i == "serial") serials[file, $1] = serials[file, $1] " " $(i + 1) } }
        END { for (key in scenes) { split(key, parts, SUBSEP); s = parts[2]; if (parts[1] != 1 || !((2, s) in scenes)) continue
            a = median(means[1, s]); b = median(means[2, s])
            printf "| %s | %.3f | %.3f | %.2f | %.3f | %.3f |\n", s, a, b, (a > 0 ? b / a : 0), median(serials[1, s]), median(serials[2, s]) } }' \
        "$1" "$2"
}

echo "== step_pile2k and step_pyramid on $threads threads"
"$bundle/run" cairn-bench-step --threads "$threads" --repetitions 3 >"$out/step.txt" 2>&1 || echo "run.sh: the step benchmark failed" >&2
# The serial part (StepStatistics::mSerialMs: the updating thread outside the parallel loops) and its phases,
# averaged over the repetitions: the part that more threads cannot shorten, and where it is
echo "scene,threads,mean_ms,p99_ms,speedup,checksum,serial_ms,serial_share,serial_narrow_ms,serial_islands_ms,serial_solve_ms,serial_finish_ms,loop_parts_joined_per_step,queued_jobs_per_step,worker_sleeps_per_step" \
    >"$out/step.csv"
awk '
    / rep [0-9]+: / { scene = $1; t = $2; sub(/threads=/, "", t); key = scene "," t
        if ($0 ~ / rep 0: /) { c = $0; sub(/.*checksum /, "", c); sub(/ +\|.*/, "", c); checksum[key] = c }
        for (i = 1; i <= NF; ++i)
            if ($i == "serial") { serial[key] += $(i + 1); share = $(i + 3); gsub(/[(%):]/, "", share); shares[key] += share
                narrow[key] += $(i + 5); islands[key] += $(i + 7); solve[key] += $(i + 9); finish[key] += $(i + 11); ++reps[key] }
        for (i = 1; i <= NF; ++i) { if ($i == "joined") joined[key] += $(i + 1); if ($i == "jobs") jobs[key] += $(i + 1)
            if ($i == "sleeps") sleeps[key] += $(i + 1) }
    }
    / median of / { scene = $1; t = $2; sub(/threads=/, "", t); key = scene "," t; n = (reps[key] > 0) ? reps[key] : 1
        for (i = 1; i <= NF; ++i) { if ($i == "mean") mean = $(i + 1); if ($i == "p99") p99 = $(i + 1) }
        if (t == 1) base[scene] = mean
        printf "%s,%s,%s,%s,%.2f,\"%s\",%.3f,%.1f,%.3f,%.3f,%.3f,%.3f,%.1f,%.1f,%.2f\n", scene, t, mean, p99, (scene in base) ? base[scene] / mean : 0,
            checksum[key], serial[key] / n, shares[key] / n, narrow[key] / n, islands[key] / n, solve[key] / n, finish[key] / n,
            joined[key] / n, jobs[key] / n, sleeps[key] / n }
' "$out/step.txt" >>"$out/step.csv"

# The same scenes at the top thread count with the job system's loop board on and off (off: a queued job per
# part of a loop, as before the board), alternated run by run: what the board saves where many threads take
# parts, measured in one sitting
topThreads=$(echo "$threads" | tr ',' '\n' | sort -n | tail -1)
# pile2k also with the broad-phase update's old bar, 1,024 active bodies whatever the thread count (the bar is
# per helper thread: 69 active bodies on 16 threads): whether the update beside the step pays where pile2k's
# steps of fewer than 1,024 active bodies did it first, serially
flatBar=$((1024 * (topThreads - 1)))
# And each loop at its own grain, as before the loops were cut for the thread count (--min-chunks-per-thread 0;
# the default gives each thread at least 4 chunks where the items allow)
echo "== step_pile2k and step_pyramid on $topThreads threads, loop board on and off, loops at their own grain;"
echo "   pile2k's update bar flat"
: >"$out/step_board.txt"
: >"$out/step_queued.txt"
: >"$out/step_own_grain.txt"
: >"$out/step_flat_bar.txt"
for round in 1 2 3; do
    for scene in step_pile2k step_pyramid; do
        "$bundle/run" cairn-bench-step --threads "$topThreads" --repetitions 1 --only "$scene" >>"$out/step_board.txt" 2>&1 ||
            echo "run.sh: the step benchmark failed (board)" >&2
        "$bundle/run" cairn-bench-step --threads "$topThreads" --repetitions 1 --only "$scene" --queued-loops \
            >>"$out/step_queued.txt" 2>&1 || echo "run.sh: the step benchmark failed (queued loops)" >&2
        "$bundle/run" cairn-bench-step --threads "$topThreads" --repetitions 1 --only "$scene" \
            --min-chunks-per-thread 0 >>"$out/step_own_grain.txt" 2>&1 ||
            echo "run.sh: the step benchmark failed (own grain)" >&2
    done
    "$bundle/run" cairn-bench-step --threads "$topThreads" --repetitions 1 --only step_pile2k \
        --update-beside-from "$flatBar" >>"$out/step_flat_bar.txt" 2>&1 ||
        echo "run.sh: the step benchmark failed (flat update bar)" >&2
done

echo "== union-find on $threads threads"
CAIRN_BENCH_THREADS=$threads "$bundle/run" cairn-bench-unionfind --benchmark_format=json \
    --benchmark_out="$out/unionfind.json" >/dev/null 2>"$out/unionfind.err" || echo "run.sh: union-find failed" >&2
echo "name,label,ns_per_union,wall_ns_per_union,find_loops_per_union,find_loops_per_find,retries_per_union" \
    >"$out/unionfind.csv"
json_rows "$out/unionfind.json" ns_per_union wall_ns_per_union find_loops_per_union find_loops_per_find \
    retries_per_union >>"$out/unionfind.csv"

echo "== stages and loops (the step's hand-offs to all threads) on $threads threads"
CAIRN_BENCH_THREADS=$threads "$bundle/run" cairn-bench-stages --benchmark_format=json \
    --benchmark_out="$out/stages.json" >/dev/null 2>"$out/stages.err" || echo "run.sh: the stage benchmark failed" >&2
echo "name,label,ns_per_stage,overhead_ns_per_stage,efficiency" >"$out/stages.csv"
json_rows "$out/stages.json" ns_per_stage overhead_ns_per_stage efficiency >>"$out/stages.csv"

echo "== contended queries, $queryThreads query threads and one mover"
CAIRN_BENCH_QUERY_THREADS=$queryThreads "$bundle/run" cairn-bench-broadphase --benchmark_filter=bp_query_contended \
    --benchmark_format=json --benchmark_out="$out/contended.json" >/dev/null 2>"$out/contended.err" ||
    echo "run.sh: the contended benchmark failed" >&2
echo "name,label,us_per_query,us_per_query_uncontended,ratio,ratio_min,ratio_max,lock_wait_us_per_thread,moves_per_s" \
    >"$out/contended.csv"
json_rows "$out/contended.json" us_per_query us_per_query_uncontended ratio ratio_min ratio_max \
    lock_wait_us_per_thread moves_per_s >>"$out/contended.csv"

if [ "$demoFrames" -gt 0 ]; then
    echo "== the demo, both modes, $cores threads, $demoFrames frames each"
    "$bundle/run" cairn-demo --world "$bundle/data/demo/world.json" --threads "$cores" --game-objects 8000 \
        --frames "$demoFrames" \
        --output "$out/demo" >"$out/demo.txt" 2>&1 || echo "run.sh: the demo exited with an error" >&2
fi

# Jolt side by side: the same two scenes stepped by Jolt, through a harness of our own on its public API that
# is built outside the repository with Jolt and bundled with CAIRN_BUNDLE_EXTRA (jolt-bench-step prints
# cairn-bench-step's line format). Only when the bundle has it, and last, while the run has time left for it
# (CAIRN_RUN_JOLT_UNTIL seconds since the start, default 420): Cairn's own figures come first
joltUntil=${CAIRN_RUN_JOLT_UNTIL:-420}
if [ -x "$bundle/bin/jolt-bench-step" ]; then
    if [ "$SECONDS" -lt "$joltUntil" ]; then
        echo "== Jolt: step_pile2k and step_pyramid on $threads threads (jolt-bench-step)"
        "$bundle/run" jolt-bench-step --threads "$threads" --repetitions 3 >"$out/jolt_step.txt" 2>&1 ||
            echo "run.sh: the Jolt harness failed" >&2
        # Per scene and thread count: the median of the runs' mean and p99 ms, the speed-up over Jolt's own 1
        # thread, and the first run's checksum
        echo "scene,threads,mean_ms,p99_ms,speedup,checksum" >"$out/jolt_step.csv"
        awk '
            function median(list,   n, v, i, j, t) { n = split(list, v, " ")
                for (i = 2; i <= n; ++i) for (j = i; j > 1 && v[j - 1] + 0 > v[j] + 0; --j) { t = v[j]; v[j] = v[j - 1]; v[j - 1] = t }
                return n == 0 ? 0 : (n % 2 ? v[(n + 1) / 2] : (v[n / 2] + v[n / 2 + 1]) / 2) }
            / rep [0-9]+: / { t = $2; sub(/threads=/, "", t); key = $1 "," t; if (!(key in seen)) { seen[key] = 1; order[++n] = key }
                for (i = 1; i <= NF; ++i) { if ($i == "mean") means[key] = means[key] " " $(i + 1); if ($i == "p99") p99s[key] = p99s[key] " " $(i + 1)
                    if ($i == "heights" && !(key in checksum)) checksum[key] = $(i + 1) } }
            END { for (k = 1; k <= n; ++k) { split(order[k], p, ","); m = median(means[order[k]]); if (p[2] == 1) base[p[1]] = m
                printf "%s,%.3f,%.3f,%.2f,%s\n", order[k], m, median(p99s[order[k]]), (p[1] in base && m > 0) ? base[p[1]] / m : 0, checksum[order[k]] } }
        ' "$out/jolt_step.txt" >>"$out/jolt_step.csv"
    else
        echo "run.sh: no time left for the Jolt harness ($SECONDS s gone; CAIRN_RUN_JOLT_UNTIL is $joltUntil)" >&2
    fi
fi

# The scaling chart: speed-up over 1 thread against threads, per scene, with the ideal line
awk -F, -v maxT="$(echo "$threads" | tr ',' '\n' | sort -n | tail -1)" '
    NR > 1 { scene[$1] = 1; x[$1, $2] = $2; y[$1, $2] = $5; ts[$2] = 1; if ($5 > top) top = $5 }
    END {
        if (maxT < 2) maxT = 2; if (top < maxT) top = maxT
        w = 480; h = 320; l = 50; b = 40
        printf "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%d\" height=\"%d\" font-family=\"sans-serif\" font-size=\"12\">\n", w + 160, h + 60
        printf "<text x=\"%d\" y=\"16\">Speed-up over 1 thread</text>\n", l
        printf "<line x1=\"%d\" y1=\"%d\" x2=\"%d\" y2=\"%d\" stroke=\"black\"/>\n", l, h, l + w, h
        printf "<line x1=\"%d\" y1=\"%d\" x2=\"%d\" y2=\"%d\" stroke=\"black\"/>\n", l, 30, l, h
        printf "<polyline fill=\"none\" stroke=\"#999\" stroke-dasharray=\"4\" points=\"%d,%d %d,%d\"/>\n", l + w / maxT, h - (h - 30) / top, l + w, h - (h - 30) * maxT / top
        printf "<text x=\"%d\" y=\"%d\" fill=\"#999\">ideal</text>\n", l + w + 5, h - (h - 30) * maxT / top
        for (t in ts) printf "<text x=\"%d\" y=\"%d\" text-anchor=\"middle\">%s</text>\n", l + w * t / maxT, h + 16, t
        printf "<text x=\"%d\" y=\"%d\" text-anchor=\"middle\">threads</text>\n", l + w / 2, h + 34
        split("#1f77b4 #d62728 #2ca02c #9467bd", colour, " ")
        k = 0
        for (s in scene) {
            ++k; pts = ""
            for (t = 1; t <= maxT; ++t) if ((s, t) in y) pts = pts sprintf("%d,%d ", l + w * t / maxT, h - (h - 30) * y[s, t] / top)
            printf "<polyline fill=\"none\" stroke=\"%s\" stroke-width=\"2\" points=\"%s\"/>\n", colour[k], pts
            printf "<text x=\"%d\" y=\"%d\" fill=\"%s\">%s</text>\n", l + w + 5, 30 + 16 * k, colour[k], s
        }
        print "</svg>"
    }' "$out/step.csv" >"$out/scaling.svg"

{
    echo "# Many-core run, $started"
    echo
    echo "$cores cores, $model (kernel $(uname -r)). Threads $threads; query threads $queryThreads."
    # The step benchmark's measure of a cache line's trip between two cores and back: what every line one
    # thread writes and another reads next costs
    grep -o -m1 "core-to-core round trip [0-9]* ns" "$out/step.txt" | sed 's/^c/C/; s/$/ (cairn-bench-step)./' || true
    echo
    echo "## Step scaling (cairn-bench-step, medians of 3; chart: scaling.svg)"
    echo
    echo "Serial: the updating thread's time outside the step's parallel loops (StepStatistics::mSerialMs), in ms a"
    echo "step and as a share of the step, then by phase: what more threads cannot shorten. Amdahl: the speed-up"
    echo "that the 1-thread run's serial share s allows on t threads, 1 / (s + (1 - s) / t); a speed-up well"
    echo "below it lost its time in the parallel parts (waits, lines crossing between cores), not in serial code."
    echo "The finish's serial part includes any wait for the broad-phase update, which runs beside the step until its"
    echo "finish (on 16 threads from 69 active bodies; its own time is the step benchmark's broadphase-update figure)."
    echo
    echo "Parts joined / jobs: per step, the loop parts that workers took from the job system's loop board and the"
    echo "jobs run through its queue; few parts joined on many threads means the updating thread ran most loops alone."
    echo "Sleeps: per step, the times a worker ran out of work for cSpinMicroseconds and slept; each is a wake-up"
    echo "later (tens of microseconds) before that worker helps again."
    echo
    echo "| scene | threads | mean ms | p99 ms | speed-up | Amdahl | checksum | serial ms (share) | serial narrow / islands / solve / finish ms | parts joined / jobs / sleeps |"
    echo "|---|---|---|---|---|---|---|---|---|---|"
    awk -F, 'NR > 1 { gsub(/"/, "", $6); if ($2 == 1) s[$1] = $8 / 100
        amdahl = ($1 in s) ? sprintf("%.2f", 1 / (s[$1] + (1 - s[$1]) / $2)) : "-"
        printf "| %s | %s | %s | %s | %s | %s | %s | %s (%s %%) | %s / %s / %s / %s | %s / %s / %s |\n", $1, $2, $3, $4, $5, amdahl, $6, $7, $8, $9, $10, $11, $12, $13, $14, $15 }' "$out/step.csv"
    echo
    echo "## The loop board at $topThreads threads (cairn-bench-step, on and off (--queued-loops) alternated, medians of 3 runs)"
    echo
    echo "| scene | board: mean ms | queued: mean ms | queued / board | board: serial ms | queued: serial ms |"
    echo "|---|---|---|---|---|---|"
    compare_runs "$out/step_board.txt" "$out/step_queued.txt"
    echo
    echo "## The loops' grain at $topThreads threads (cairn-bench-step, alternated with the rows above, medians of 3 runs)"
    echo
    echo "Cut: each loop over bodies, pairs or joints cut so that every thread has at least 4 chunks where the items"
    echo "allow (the default; a chunk keeps 4 us of estimated work). Own: each loop at the grain it has on 2 threads"
    echo "(--min-chunks-per-thread 0)."
    echo
    echo "| scene | cut: mean ms | own: mean ms | own / cut | cut: serial ms | own: serial ms |"
    echo "|---|---|---|---|---|---|"
    compare_runs "$out/step_board.txt" "$out/step_own_grain.txt"
    echo
    echo "## The broad-phase update's bar at $topThreads threads (cairn-bench-step, step_pile2k, alternated with the rows above, medians of 3 runs)"
    echo
    echo "Per helper: the update runs beside the step from 1,024 active bodies per helper thread (the default). Flat:"
    echo "from 1,024 active bodies whatever the thread count (--update-beside-from $flatBar); below, the step does it"
    echo "first, a serial stretch."
    echo
    echo "| scene | per helper: mean ms | flat: mean ms | flat / per helper | per helper: serial ms | flat: serial ms |"
    echo "|---|---|---|---|---|---|"
    compare_runs "$out/step_board.txt" "$out/step_flat_bar.txt"
    echo
    echo "## Union-find (cairn-bench-unionfind)"
    echo
    echo "| benchmark | graph | ns per union | wall ns per union | find loops per find | retries per union |"
    echo "|---|---|---|---|---|---|"
    awk -F, 'NR > 1 { printf "| %s | %s | %.2f | %.2f | %.3f | %.4f |\n", $1, $2 "," $3, $4, $5, $7, $8 }' "$out/unionfind.csv" | sed 's/"//g'
    echo
    echo "## Stages and loops (cairn-bench-stages: 1,024 RunStages stages or ParallelFor loops of one part per thread, the"
    echo "work of each shared out; a settled pyramid's step makes some 200 stages, every step a dozen or more loops)"
    echo
    echo "| benchmark (work ns each / threads) | threads | ns each | overhead ns each | efficiency |"
    echo "|---|---|---|---|---|"
    awk -F, 'NR > 1 { printf "| %s | %s | %.0f | %.0f | %.2f |\n", $1, $2, $3, $4, $5 }' "$out/stages.csv" | sed 's/"//g'
    echo
    echo "## Contended queries (bp_query_contended: Q query threads and one mover; medians of 5)"
    echo
    echo "| benchmark | tree, query threads | us per query | uncontended | ratio (min-max) | lock wait us per thread | moves/s |"
    echo "|---|---|---|---|---|---|---|"
    awk -F, 'NR > 1 { printf "| %s | %s | %.3f | %.3f | %.2f (%.2f-%.2f) | %.0f | %.0f |\n", $1, $2 "," $3, $4, $5, $6, $7, $8, $9, $10 }' "$out/contended.csv" | sed 's/"//g'
    if [ -f "$out/demo.txt" ]; then
        echo
        echo "## Demo (cairn-demo --threads $cores --game-objects 8000 --frames $demoFrames)"
        echo
        echo '```'
        grep -iE "lock|query|wait|per thread|frame" "$out/demo.txt" | tail -30
        echo '```'
    fi
    if [ -s "$out/jolt_step.csv" ]; then
        echo
        echo "## Jolt side by side (jolt-bench-step on this machine, medians of 3; Cairn's columns from the step table)"
        echo
        grep -m1 "^jolt-bench-step:" "$out/jolt_step.txt" || true
        echo
        echo "| scene | threads | Cairn mean ms | Jolt mean ms | Cairn / Jolt | Cairn speed-up | Jolt speed-up | Jolt p99 ms | Jolt checksum |"
        echo "|---|---|---|---|---|---|---|---|---|"
        awk -F, 'FNR == 1 { file++; next } file == 1 { cairn[$1 "," $2] = $3; up[$1 "," $2] = $5; next }
            { k = $1 "," $2; c = (k in cairn) ? cairn[k] : ""
              printf "| %s | %s | %s | %s | %s | %s | %s | %s | %s |\n", $1, $2, c, $3, (c != "" && $3 > 0) ? sprintf("%.2f", c / $3) : "-",
                  (k in up) ? up[k] : "-", $5, $4, $6 }' "$out/step.csv" "$out/jolt_step.csv"
    fi
} >"$out/summary.md"
cat "$out/summary.md"
