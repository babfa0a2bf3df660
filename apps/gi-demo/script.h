// gi-demo --script FILE: steps that drive the demo exactly as a user would, through the same
// calls the panel and the keys make. One step per line, '#' starts a comment:
//   frames N                 render N frames (the clock advances 1/30 s per frame unless paused)
//   key KEYS N               hold keys for N frames: w a s d q e shift ctrl joined by '+'
//   look DX DY               move the mouse by (DX, DY) pixels (turns the camera) next frame
//   camera X Y Z YAW PITCH   place the camera (degrees; yaw 0 looks down -z)
//   effect NAME on|off       switch an effect
//   set OWNER.KEY=VALUE      change an effect's or the engine's setting
//   preset NAME|none         switch the quality preset
//   view NAME                show a resource (G-buffer channel, effect output, shadow maps)
//   resize W H               resize the window (the renderer follows the window)
//   pause on|off             stop or restart the clock
//   step                     advance the stopped clock by one frame's time
//   time T                   set the clock
//   accuracy EFFECT SPP      compare the last frame of EFFECT with the CPU reference (SPP
//                            samples per pixel; waits) and print its NRMSE; needs a frame
//                            rendered since the last effect, view, preset or size change
//   screenshot PATH          write the rendered image (without the panel) as PNG
//   print passes|views|timings|memory|camera   print to stdout (views: what `view` takes)
//   copy FROM TO             copy a file (e.g. an edited shader into --shader-dir), as a new
//                            file renamed over TO (as a build or an editor replaces one)
//   reload                   check the plugin modules and the effects' GLSL now (hot reload;
//                            the window checks every 0.5 s): per rebuilt module one line
//                            "plugin reload: FILE: EFFECTS; settings kept: EFFECT.KEY, ..." or
//                            "plugin reload: error: <why>"; then one line "reload: N shader(s)
//                            rebuilt", or "reload: no change", or "reload: error: <message>"
#pragma once

#include <string>
#include <vector>

namespace demo {

struct ScriptStep {
  std::string verb;
  std::vector<std::string> args;
  int line = 0;
};

// Parses and checks a script (verbs, argument counts, numbers); throws gi::Error naming the
// file and line.
std::vector<ScriptStep> loadScript(const std::string& path);
// A number argument of `step`, or gi::Error naming the line.
double scriptNumber(const ScriptStep& step, size_t arg, const std::string& path);

}  // namespace demo
