// atmos CLI: `atmos irradiance` (the sun's direct and the sky's diffuse
// irradiance on a horizontal plane: a renderer's sun lamp and ambient).
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include "atmos/atmosphere.h"
#include "atmos/error.h"
#include "atmos/model.h"
#include "atmos/view.h"
#include "base/parallel.h"
#include "cli_common.h"
#include "harness/irradiance.h"

namespace atmos::cli {

namespace {

struct IrradianceOptions {
    std::string sun;
    std::string camera;
};

int CmdIrradiance(const CommonOptions& common, const IrradianceOptions& io) {
    if (io.sun.empty()) Fail("irradiance needs --sun elevation=DEG[,azimuth=DEG]");
    const Vec3d sun = ParseSunSpec(io.sun);
    CameraSpec camera;
    if (!io.camera.empty()) {
        camera = ParseCameraSpec(io.camera);
        CheckCameraSpec(camera, 0, 0);
        if (camera.oriented || camera.fov_deg != 0.0 ||
            camera.projection != Projection::kPerspective) {
            Fail("irradiance: --camera takes only altitude=M (the plane faces up)");
        }
    }
    ThreadLimit limit(common.threads);
    const BackendScope backend(ParseBackend(common.backend));
    const AtmosphereParameters atmosphere = LoadAtmosphere(common.atmosphere, common.sets);
    std::unique_ptr<Model> model = CreateModel(GivenModel(common));
    RequireQuantity(model->Info(), Quantity::kRadiance);
    PrepareModel(common, atmosphere, model.get());
    const double elevation = std::asin(Clamp(sun.z, -1.0, 1.0)) * (180.0 / kPi);
    const HorizontalIrradiance e =
        ComputeHorizontalIrradiance(*model, atmosphere, camera.altitude_m, elevation);
    std::fputs(HorizontalIrradianceCsv(e).c_str(), stdout);
    if (!common.quiet) {
        std::fprintf(stderr,
                     "%s: diffuse by %d x %d nodes (mu x azimuth; %d x %d gave %.9g,%.9g,%.9g); "
                     "per unit solar irradiance times the atmosphere's solar_irradiance\n",
                     common.model.c_str(), e.mu_nodes, e.azimuth_nodes, e.mu_nodes / 2,
                     e.azimuth_nodes / 2, e.diffuse_coarse.x, e.diffuse_coarse.y,
                     e.diffuse_coarse.z);
    }
    return 0;
}

}  // namespace

Command AddIrradianceCommand(CLI::App* root) {
    auto common = std::make_shared<CommonOptions>();
    auto io = std::make_shared<IrradianceOptions>();
    Command c;
    c.app = root->add_subcommand(
        "irradiance",
        "the sun's direct and the sky's diffuse irradiance on a horizontal plane (CSV: "
        "quantity,r,g,b; bruneton also its irradiance table)");
    AddCommonOptions(c.app, common.get());
    AddBackendOption(c.app, &common->backend);
    c.app->add_option("--sun", io->sun,
                      "elevation=DEG[,azimuth=DEG] or time=ISO-8601,latitude=DEG,longitude=DEG (as "
                      "render --sun)");
    c.app->add_option("--camera", io->camera, "altitude=M: the plane's height above the ground");
    c.run = [common, io] { return CmdIrradiance(*common, *io); };
    return c;
}

}  // namespace atmos::cli
