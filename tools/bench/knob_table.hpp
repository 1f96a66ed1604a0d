// The accuracy-vs-time table and plot the per-system knob benches share
// (gases, vdb): every setting's time and error against its system's exact
// reference, its ratio to the default's time, and the Pareto front, printed
// as markdown and written as gnuplot data + script + PNG (as accuracy.cpp).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "spawn.hpp"
#include "splatfx/image.hpp"

namespace bench {

struct KnobRow {
    std::string knob, setting;
    double ms = 0.0;     // the setting's cost (what the command says it times)
    double rmse = 0.0;   // premultiplied RGBA over black, against the reference
    double maxErr = 0.0; // largest channel difference of any pixel
    std::string extra;   // one more column (cells, splats)
    bool isDefault = false;
    bool pareto = false;
};

// RMSE over every channel of every pixel, and the largest difference.
inline void imageError(const splatfx::Image& a, const splatfx::Image& b, double& rmse, double& maxErr) {
    double sum = 0.0;
    maxErr = 0.0;
    for (std::size_t i = 0; i < a.pixels.size() && i < b.pixels.size(); ++i) {
        const double d = double(a.pixels[i]) - double(b.pixels[i]);
        sum += d * d;
        maxErr = std::max(maxErr, std::abs(d));
    }
    rmse = a.pixels.empty() ? 0.0 : std::sqrt(sum / double(a.pixels.size()));
}

// A row is on the front when no other row is at least as fast and as accurate, and better in one.
inline void markPareto(std::vector<KnobRow>& rows) {
    for (KnobRow& r : rows) {
        r.pareto = true;
        for (const KnobRow& o : rows)
            if (&o != &r && o.ms <= r.ms && o.rmse <= r.rmse && (o.ms < r.ms || o.rmse < r.rmse)) r.pareto = false;
    }
}

inline void printTable(const std::vector<KnobRow>& rows, const char* timeHeader, const char* extraHeader) {
    double defaultMs = 0.0;
    for (const KnobRow& r : rows)
        if (r.isDefault) defaultMs = r.ms;
    std::string extraRule;
    for (const char* c = extraHeader; *c; ++c)
        if (*c == '|') extraRule += " ---: |";
    std::printf("\n| knob | setting | %s | vs default | RMSE | max error | %s | Pareto |\n| --- | --- | ---: | ---: | ---: | ---: | ---: |%s --- |\n",
                timeHeader, extraHeader, extraRule.c_str());
    for (const KnobRow& r : rows)
        std::printf("| %s | %s%s | %.3f | %.2fx | %.5f | %.4f | %s | %s |\n", r.knob.c_str(), r.setting.c_str(), r.isDefault ? " (default)" : "",
                    r.ms, defaultMs > 0.0 ? r.ms / defaultMs : 0.0, r.rmse, r.maxErr, r.extra.c_str(), r.pareto ? "yes" : "");
}

// DIR/NAME.dat (one block per knob, then all rows, then the front), DIR/NAME.gp,
// and gnuplot run in DIR for NAME_knobs.png and NAME_pareto.png. Returns false
// (with a message) when gnuplot cannot run.
inline bool writePlot(const std::vector<KnobRow>& rows, const std::string& dir, const std::string& name, const std::string& title,
                      const std::string& timeLabel) {
    std::vector<std::string> knobs;
    for (const KnobRow& r : rows)
        if (std::find(knobs.begin(), knobs.end(), r.knob) == knobs.end()) knobs.push_back(r.knob);
    {
        std::ofstream d(dir + "/" + name + ".dat");
        for (const std::string& k : knobs) {
            d << "# " << k << "\n";
            for (const KnobRow& r : rows)
                if (r.knob == k) d << r.ms << " " << r.rmse << " \"" << r.setting << "\"\n";
            d << "\n\n";
        }
        d << "# all settings\n";
        for (const KnobRow& r : rows) d << r.ms << " " << r.rmse << " \"" << r.knob << ": " << r.setting << "\"\n";
        d << "\n\n# pareto front\n";
        std::vector<KnobRow> front;
        for (const KnobRow& r : rows)
            if (r.pareto) front.push_back(r);
        std::sort(front.begin(), front.end(), [](const KnobRow& x, const KnobRow& y) { return x.ms < y.ms; });
        for (const KnobRow& r : front) d << r.ms << " " << r.rmse << " \"" << r.knob << ": " << r.setting << "\"\n";
    }
    std::ofstream gp(dir + "/" + name + ".gp");
    const int cols = std::min<int>(3, int(knobs.size())), rowsN = int(knobs.size() + cols - 1) / cols;
    gp << "# Written by splatfx-bench " << name << "; run: gnuplot " << name << ".gp\n"
       << "set terminal pngcairo size " << 420 * cols << "," << 330 * rowsN << " font 'sans,9'\n"
       << "set output '" << name << "_knobs.png'\n"
       << "set multiplot layout " << rowsN << "," << cols << " title '" << title << "'\n"
       << "set logscale y\nset grid\nset xrange [0:*]\nset xlabel '" << timeLabel << "'\nset ylabel 'RMSE vs reference'\nset key off\n"
       << "set offsets graph 0.12, graph 0.12, graph 0.1, graph 0.1\n";
    for (std::size_t k = 0; k < knobs.size(); ++k)
        gp << "set title '" << knobs[k] << "'\nplot '" << name << ".dat' index " << k << " using 1:2 with linespoints pt 7 lc rgb '#c0392b', "
           << "'' index " << k << " using 1:2:3 with labels offset 0,0.9 font 'sans,8'\n";
    gp << "unset multiplot\n"
       << "set terminal pngcairo size 900,640 font 'sans,10'\nset output '" << name << "_pareto.png'\nset key top right\nset autoscale x\n"
       << "set title 'All settings against the reference, and their Pareto front'\n"
       << "plot '" << name << ".dat' index " << knobs.size() << " using 1:2 with points pt 6 lc rgb '#7f8c8d' title 'setting', "
       << "'' index " << knobs.size() + 1 << " using 1:2 with linespoints pt 7 lw 2 lc rgb '#c0392b' title 'Pareto front', "
       << "'' index " << knobs.size() + 1 << " using 1:2:3 with labels left offset 1,0 font 'sans,8' notitle\n";
    gp.close();
    const cli::SpawnResult r = cli::spawn({.argv = {"gnuplot", name + ".gp"}, .workingDir = dir});
    if (!r.started || r.exitCode != 0) {
        std::fprintf(stderr, "%s: gnuplot failed on %s/%s.gp%s%s (install gnuplot-nox or pass --no-plots)\n", name.c_str(), dir.c_str(), name.c_str(),
                     r.started ? "" : ": ", r.error.c_str());
        return false;
    }
    std::printf("wrote %s/%s_knobs.png and %s/%s_pareto.png (data: %s.dat, script: %s.gp)\n", dir.c_str(), name.c_str(), dir.c_str(), name.c_str(),
                name.c_str(), name.c_str());
    return true;
}

} // namespace bench
