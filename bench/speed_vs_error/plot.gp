# PSNR against time per frame, one colour per scene, from speed_vs_error's CSV.
# gnuplot -e "csv='speed_vs_error.csv'; out='speed_vs_error.png'; scenes='a b'; note='...'" plot.gp
#
# Solid line: plain classification, dashed: pre-integrated, both with
# empty-space skipping on and the step halving from 2 to 0.125 voxel along
# each line; crosses: the same cases with skipping off (same error, more
# time). The ringed point is the scene file's own settings.
set terminal pngcairo size 1200,800 font ",11"
set output out
set key outside right top
set logscale x
set grid
set xlabel "time per frame (s, median, 2 threads, log scale)"
set ylabel "PSNR (dB) of linear RGBA against the double-precision reference"
set title "speed vs error: linear RGBA error against time per frame".(exists("note") ? "\n".note : "") noenhanced

# Columns: 1 scene, 6 preintegrated, 7 skipping, 8 scene_default, 13 median_s, 22 psnr_db.
# Each series is filtered by awk so that its points form one unbroken line.
rows(name, cond) = sprintf("< awk -F, '!/^#/ && $1 == \"%s\" && %s { print $13, $22 }' '%s'", name, cond, csv)
plain(n) = rows(n, "$6 == 0 && $7 == 1")
preint(n) = rows(n, "$6 == 1 && $7 == 1")
noskip(n) = rows(n, "$7 == 0")
own(n) = rows(n, "$8 == 1")
set key noenhanced
set datafile separator whitespace

plot for [i=1:words(scenes)] plain(word(scenes, i)) using 1:2 \
       with linespoints lc i lw 2 pt 7 ps 1.2 title word(scenes, i)." plain", \
     for [i=1:words(scenes)] preint(word(scenes, i)) using 1:2 \
       with linespoints lc i lw 2 dt 2 pt 5 ps 1.0 title word(scenes, i)." pre-integrated", \
     for [i=1:words(scenes)] noskip(word(scenes, i)) using 1:2 \
       with points lc i pt 2 ps 1.0 notitle, \
     for [i=1:words(scenes)] own(word(scenes, i)) using 1:2 \
       with points lc i pt 6 ps 3 lw 2 notitle
