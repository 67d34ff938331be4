// The full downstream program: one call into each installed library, so that linking it resolves
// every library's own dependencies, and one check of a result.
#include <cstdio>
#include <msm/cpu/techniques.h>
#include <msm/evaluate/functions.h>
#include <msm/oracle/moment_oracle.h>
#include <msm/reference/reference.h>
#include <msm/scene/scene.h>
#ifdef MSM_DOWNSTREAM_RENDER
#include <msm/render/renderer.h>
#include <msm/viewer/view_file.h>
#endif
#ifdef MSM_DOWNSTREAM_VIEWER
#include <msm/viewer/viewer.h>
#endif

int main() {
  const msm::scene::Scene scene = msm::scene::builtin_scene("disc");
  msm::reference::Settings settings;
  settings.width = 16;
  settings.height = 9;
  const msm::reference::Result truth = msm::reference::render(scene, settings);
  const msm::oracle::CantelliBounds cantelli = msm::oracle::cantelli_bounds(0.5, 0.01, 0.7);
  std::printf("%zu techniques, %zu candidate functions, %llu rays, Cantelli %.3f\n", msm::techniques().size(),
              msm::evaluate::candidate_functions().size(), static_cast<unsigned long long>(truth.rays), cantelli.lower);
#ifdef MSM_DOWNSTREAM_RENDER
  const msm::viewer::View view = msm::viewer::default_view("disc", scene);
  std::printf("%zu rendered techniques, view %s\n", msm::render::rendered_techniques().size(),
              msm::viewer::view_json(view).dump().substr(0, 40).c_str());
#endif
#ifdef MSM_DOWNSTREAM_VIEWER
  if (&msm::viewer::run_viewer == nullptr) return 1; // linked, not run: it opens a window
#endif
  return truth.rays > 0 && truth.visibility.width() == 16 ? 0 : 1;
}
