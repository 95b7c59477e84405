// Turns RenderInputs into DIR/NNNNNN.png and, at the end, DIR/summary.png. The live node and the
// offline log renderer both write through this class.
#pragma once

#include <memory>
#include <string>

#include "density_map.hpp"
#include "render_config.hpp"
#include "render_input.hpp"
#include "run_state.hpp"

namespace dlslot::renderer {

class FrameWriter {
 public:
  // Creates out_dir when needed; throws std::runtime_error naming it when that fails.
  FrameWriter(std::string out_dir, const RendererConfig& cfg);

  // Draws and writes one frame, adds its kept points to the summary map; returns the file.
  std::string write(const RenderInput& in);
  // Writes the run summary; returns the file ("" when the summary is disabled).
  std::string writeSummary(const RunSummary& run);
  std::string framePath(int frame) const;

 private:
  std::string out_dir_;
  RendererConfig cfg_;
  std::unique_ptr<DensityMap> map_;
};

}  // namespace dlslot::renderer
