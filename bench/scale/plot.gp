# bench/scale's plot: gnuplot -e "csv='RESULTS.csv'; png='RESULTS.png'" plot.gp
# Left: time to the first frame against ranks (pvr-node --batch and
# pvrd + pvrsh, cold and warm) beside the file's cold and warm read.
# Right: the phases of the batch runs' first frame (max over ranks).
set datafile separator ","
set terminal pngcairo size 1200,500
set output png
stats "< grep '^read,1,cold' ".csv using 5 nooutput name "cold"
stats "< grep '^read,1,warm' ".csv using 5 nooutput name "warm"
set multiplot layout 1,2
set title "time to the first frame (512x512)"
set xlabel "ranks"; set ylabel "seconds"; set logscale x 2; set key top left; set yrange [0:*]
plot "< grep '^batch,.*,cold,' ".csv using 2:5 with linespoints title "pvr-node --batch, cold", \
     "< grep '^batch,.*,warm,' ".csv using 2:5 with linespoints title "pvr-node --batch, warm", \
     "< grep '^pvrsh,.*,cold,' ".csv using 2:5 with linespoints title "pvrd + pvrsh, cold", \
     "< grep '^pvrsh,.*,warm,' ".csv using 2:5 with linespoints title "pvrd + pvrsh, warm", \
     cold_mean with lines dashtype 2 title "cold sequential read", \
     warm_mean with lines dashtype 3 title "warm sequential read"
set title "pvr-node --batch: phases (max over ranks)"
unset logscale x; set style data histograms; set style histogram rowstacked; set style fill solid; set key outside; set xtics rotate by -45
plot "< grep '^batch,' ".csv using 7:xtic(sprintf("%d %s", column(2), strcol(3))) title "start", \
     '' using 8 title "read", '' using 9 title "prep", '' using 10 title "dist", '' using 11 title "rend", \
     '' using 12 title "comp", '' using 13 title "comm", '' using 14 title "send", '' using 15 title "write" linecolor rgb "gray40"
unset multiplot
