// Free cameras, projections, sample --ground/--sun-disc and the horizontal
// irradiance (issue 31; conventions in docs/views.md).
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/error.h"
#include "atmos/image.h"
#include "atmos/model.h"
#include "atmos/sun_position.h"
#include "atmos/view.h"
#include "harness/irradiance.h"

namespace fs = std::filesystem;
using namespace atmos;

namespace {

double D(float v) { return static_cast<double>(v); }

const AtmosphereParameters& Earth() {
    static const AtmosphereParameters atm = EarthAtmosphere();
    return atm;
}

// A prepared model, made once per process.
const Model& Prepared(const std::string& name,
                      const std::map<std::string, std::string>& options = {}) {
    static std::map<std::string, std::unique_ptr<Model>> models;
    std::string key = name;
    for (const auto& [k, v] : options) key += ":" + k + "=" + v;
    std::unique_ptr<Model>& m = models[key];
    if (!m) {
        m = CreateModel(name, options);
        m->Prepare(Earth());
    }
    return *m;
}

Image RenderCustom(const Model& model, const CameraSpec& spec, const Vec3d& sun, int w, int h,
                   bool sun_disc = false) {
    CheckCameraSpec(spec, w, h);
    RenderRequest request;
    request.view = CustomView(spec, sun, Earth());
    request.width = w;
    request.height = h;
    request.sun_disc = sun_disc;
    request.show_progress = false;
    Image image;
    model.Render(request, &image);
    return image;
}

// The sample query of a world-frame direction seen from `altitude`.
SampleQuery QueryFor(const Vec3d& dir, const Vec3d& sun, double altitude) {
    SampleQuery q;
    q.altitude_m = altitude;
    q.mu = Clamp(dir.z, -1.0, 1.0);
    q.mu_s = Clamp(sun.z, -1.0, 1.0);
    const double dh = std::hypot(dir.x, dir.y), sh = std::hypot(sun.x, sun.y);
    double c = 1.0;
    if (dh > 1e-12 && sh > 1e-12) c = Clamp((dir.x * sun.x + dir.y * sun.y) / (dh * sh), -1.0, 1.0);
    q.azimuth_deg = std::acos(c) * 180.0 / kPi;
    q.ground = 1;
    return q;
}

// Every pixel of a free render equals `sample --ground` at its direction.
void ExpectPixelsMatchSample(const Model& model, const CameraSpec& spec, int w, int h) {
    const Vec3d sun = DirectionFromAzimuthElevation(40.0, 12.0);
    const Image image = RenderCustom(model, spec, sun, w, h);
    const Camera camera = MakeCameraFromSpec(spec, Earth());
    std::vector<SampleQuery> queries;
    std::vector<std::pair<int, int>> pixels;
    int zero_rays = 0, ground = 0;
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            const Vec3d d = camera.RayDirection(x, y, w, h);
            if (d.x == 0.0 && d.y == 0.0 && d.z == 0.0) {
                const Rgb v = image.Get(x, y);
                EXPECT_EQ(v.x + v.y + v.z, 0.0f) << x << "," << y;
                ++zero_rays;
                continue;
            }
            queries.push_back(QueryFor(d, sun, spec.altitude_m));
            pixels.emplace_back(x, y);
            if (d.z < -0.05) ++ground;
        }
    }
    const std::vector<SampleAnswer> answers = model.Sample(queries);
    int bad = 0;
    for (size_t i = 0; i < queries.size(); ++i) {
        const Rgb p = image.Get(pixels[i].first, pixels[i].second);
        for (int c = 0; c < 3; ++c) {
            const double want = D(answers[i].radiance[c]) * Earth().solar_irradiance[c];
            if (std::fabs(D(p[c]) - want) > 2e-4 * std::fabs(want) + 1e-7) {
                if (++bad < 5) {
                    ADD_FAILURE() << ProjectionName(spec.projection) << " pixel ("
                                  << pixels[i].first << ", " << pixels[i].second << ") channel "
                                  << c << ": " << p[c] << " vs sample " << want;
                }
            }
        }
    }
    EXPECT_EQ(bad, 0);
    // The whole-sphere projections (and a fisheye wider than 180 degrees) see the ground.
    if (spec.projection != Projection::kPerspective &&
        (spec.projection != Projection::kFisheye || spec.fov_deg > 180.0)) {
        EXPECT_GT(ground, 0) << "no lit ground";
    }
    (void)zero_rays;
}

TEST(Camera, EveryProjectionsPixelsEqualSampleNaive) {
    const Model& m = Prepared("naive", {{"steps", "8"}, {"light-steps", "4"}});
    CameraSpec spec;
    spec.altitude_m = 1000.0;
    spec.projection = Projection::kEquirect;
    ExpectPixelsMatchSample(m, spec, 48, 24);
    spec.projection = Projection::kFisheye;
    spec.fov_deg = 220.0;  // below the horizon too
    ExpectPixelsMatchSample(m, spec, 24, 20);
    spec.fov_deg = 0.0;
    spec.projection = Projection::kCubemap;
    ExpectPixelsMatchSample(m, spec, 96, 16);
    spec.projection = Projection::kEqualArea;
    ExpectPixelsMatchSample(m, spec, 24, 24);
    CameraSpec p;
    p.altitude_m = 12000.0;
    p.azimuth_deg = 120.0;
    p.elevation_deg = -20.0;
    p.roll_deg = 15.0;
    p.fov_deg = 70.0;
    p.oriented = true;
    ExpectPixelsMatchSample(m, p, 24, 16);
}

TEST(Camera, EveryProjectionsPixelsEqualSampleTableModels) {
    for (const char* name : {"bruneton", "hillaire"}) {
        SCOPED_TRACE(name);
        const Model& m = Prepared(name);
        CameraSpec spec;
        spec.altitude_m = 500.0;
        for (Projection pr : {Projection::kEquirect, Projection::kFisheye, Projection::kCubemap,
                              Projection::kEqualArea}) {
            spec.projection = pr;
            const int h = 16;
            const int w = pr == Projection::kEquirect ? 32 : pr == Projection::kCubemap ? 96 : 16;
            ExpectPixelsMatchSample(m, spec, w, h);
        }
    }
}

// The conventions, from their definitions (docs/views.md), not from the code.
TEST(Camera, EquirectAndFisheyeConventions) {
    CameraSpec spec;
    spec.projection = Projection::kEquirect;
    const Camera c = MakeCameraFromSpec(spec, Earth());
    const int w = 360, h = 180;
    // Column x: azimuth 360 (x + 0.5) / W clockwise from north; row y: elevation 90 - 180 (y + 0.5)
    // / H.
    for (int x : {0, 89, 180, 271, 359}) {
        for (int y : {0, 45, 90, 179}) {
            const Vec3d want =
                DirectionFromAzimuthElevation(360.0 * (x + 0.5) / w, 90.0 - 180.0 * (y + 0.5) / h);
            const Vec3d got = c.RayDirection(x, y, w, h);
            EXPECT_NEAR(Length(got - want), 0.0, 1e-12) << x << "," << y;
        }
    }
    // East a quarter of the way across (+x), north at the edges (+y).
    EXPECT_GT(c.RayDirection(89, 89, w, h).x, 0.999);
    EXPECT_GT(c.RayDirection(0, 89, w, h).y, 0.999);
    spec.projection = Projection::kFisheye;
    const Camera f = MakeCameraFromSpec(spec, Earth());
    const int n = 101;                                  // odd: a centre pixel
    EXPECT_GT(f.RayDirection(50, 50, n, n).z, 0.9999);  // zenith at the centre
    const Vec3d top = f.RayDirection(50, 0, n, n), left = f.RayDirection(0, 50, n, n);
    EXPECT_GT(top.y, 0.999);   // north up (on the horizon: 90 degrees at the edge)
    EXPECT_GT(left.x, 0.999);  // east left
    EXPECT_NEAR(top.z, std::cos(kPi / 2 * 100.0 / 101.0), 1e-12);  // equidistant
    const Vec3d corner = f.RayDirection(0, 0, n, n);
    EXPECT_EQ(Length(corner), 0.0);  // outside the image circle
}

// OpenGL's face selection (the GL 4.6 specification, table 8.19), written
// from the table: direction in GL axes -> face, s, t.
void GlFace(const Vec3d& g, int* face, double* s, double* t) {
    const double ax = std::fabs(g.x), ay = std::fabs(g.y), az = std::fabs(g.z);
    double sc, tc, ma;
    if (ax >= ay && ax >= az) {
        ma = ax;
        if (g.x > 0) {
            *face = 0;
            sc = -g.z;
            tc = -g.y;
        } else {
            *face = 1;
            sc = g.z;
            tc = -g.y;
        }
    } else if (ay >= az) {
        ma = ay;
        if (g.y > 0) {
            *face = 2;
            sc = g.x;
            tc = g.z;
        } else {
            *face = 3;
            sc = g.x;
            tc = -g.z;
        }
    } else {
        ma = az;
        if (g.z > 0) {
            *face = 4;
            sc = g.x;
            tc = -g.y;
        } else {
            *face = 5;
            sc = -g.x;
            tc = -g.y;
        }
    }
    *s = 0.5 * (sc / ma + 1.0);
    *t = 0.5 * (tc / ma + 1.0);
}

// World (east, north, up) to GL (GL +X = east, +Y = up, +Z = south).
Vec3d ToGl(const Vec3d& d) { return Vec3d(d.x, d.z, -d.y); }

TEST(Camera, CubemapFollowsOpenGlsTable) {
    CameraSpec spec;
    spec.projection = Projection::kCubemap;
    const Camera c = MakeCameraFromSpec(spec, Earth());
    const int n = 32;
    // Face centres: +X east, -X west, +Y up, -Y down, +Z south, -Z north.
    const Vec3d centres[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 0, 1}, {0, 0, -1}, {0, -1, 0}, {0, 1, 0}};
    for (int f = 0; f < 6; ++f) {
        const Vec3d d = c.MappedDirection(f * n + 0.5 * n, 0.5 * n, 6 * n, n);
        EXPECT_NEAR(Length(d - centres[f]), 0.0, 1e-12) << "face " << f;
    }
    // Every pixel maps back to itself through GL's selection.
    for (int y = 0; y < n; ++y) {
        for (int x = 0; x < 6 * n; ++x) {
            int face;
            double s, t;
            GlFace(ToGl(c.RayDirection(x, y, 6 * n, n)), &face, &s, &t);
            EXPECT_EQ(face, x / n);
            EXPECT_NEAR(s * n, x % n + 0.5, 1e-9);
            EXPECT_NEAR(t * n, y + 0.5, 1e-9);
        }
    }
}

TEST(Camera, CubeFacesAgreeAlongSharedEdges) {
    const Model& m = Prepared("naive", {{"steps", "8"}, {"light-steps", "4"}});
    CameraSpec spec;
    spec.projection = Projection::kCubemap;
    spec.altitude_m = 2000.0;
    const int n = 48;
    const Vec3d sun = DirectionFromAzimuthElevation(30.0, 20.0);
    const Image image = RenderCustom(m, spec, sun, 6 * n, n);
    const Camera c = MakeCameraFromSpec(spec, Earth());
    int edges = 0;
    double worst = 0.0;
    for (int f = 0; f < 6; ++f) {
        for (int k = 0; k < n; ++k) {
            // The four edges of face f: pixel (i, j) in the face.
            const int ij[4][2] = {{0, k}, {n - 1, k}, {k, 0}, {k, n - 1}};
            for (const auto& p : ij) {
                const int x = f * n + p[0], y = p[1];
                const Vec3d g = ToGl(c.RayDirection(x, y, 6 * n, n));
                // Mirror across the plane of the edge the pixel touches: the
                // pixel across the edge on the neighbouring face (GL's table).
                int face;
                double s, t;
                GlFace(g, &face, &s, &t);
                const double a[3] = {g.x, g.y, g.z};
                int major = 0;
                for (int i = 1; i < 3; ++i) {
                    if (std::fabs(a[i]) > std::fabs(a[major])) major = i;
                }
                // The second-largest component names the neighbouring face.
                int second = major == 0 ? 1 : 0;
                for (int i = 0; i < 3; ++i) {
                    if (i != major && std::fabs(a[i]) > std::fabs(a[second])) second = i;
                }
                if (std::fabs(std::fabs(a[second]) - std::fabs(a[major])) > 2.5 / n) continue;
                double b[3] = {a[0], a[1], a[2]};
                const double sign = (a[major] > 0) == (a[second] > 0) ? 1.0 : -1.0;
                b[major] = sign * a[second];
                b[second] = sign * a[major];
                int face2;
                double s2, t2;
                GlFace(Vec3d(b[0], b[1], b[2]), &face2, &s2, &t2);
                EXPECT_NE(face2, face);
                const int x2 = face2 * n + Clamp(static_cast<int>(s2 * n), 0, n - 1);
                const int y2 = Clamp(static_cast<int>(t2 * n), 0, n - 1);
                const Rgb v1 = image.Get(x, y), v2 = image.Get(x2, y2);
                for (int ch = 0; ch < 3; ++ch) {
                    const double rel = std::fabs(D(v1[ch]) - D(v2[ch])) /
                                       std::max(1e-9, D(std::max(v1[ch], v2[ch])));
                    worst = std::max(worst, rel);
                }
                ++edges;
            }
        }
    }
    EXPECT_GT(edges, 6 * 4 * n / 2);
    // Neighbours a pixel apart (1.9 degrees): the sky changes by a few percent
    // at most between them; a face turned or flipped differs by far more.
    EXPECT_LT(worst, 0.06) << "edge pixels " << edges;
}

TEST(Camera, EqualAreaIsPbrtsOctahedralMapAndEqualArea) {
    CameraSpec spec;
    spec.projection = Projection::kEqualArea;
    const Camera c = MakeCameraFromSpec(spec, Earth());
    const int n = 64;
    // Centre: zenith; corners: nadir; the right edge's middle +x (east), the
    // bottom edge's middle +y (north) (pbrt-v4's EqualAreaSquareToSphere).
    EXPECT_GT(c.MappedDirection(32, 32, n, n).z, 0.99999);
    EXPECT_LT(c.MappedDirection(0, 0, n, n).z, -0.99999);
    EXPECT_GT(c.MappedDirection(64, 32, n, n).x, 0.99999);
    EXPECT_GT(c.MappedDirection(32, 64, n, n).y, 0.99999);
    EXPECT_LT(c.MappedDirection(32, 0, n, n).y, -0.99999);
    // Equal area: each pixel's solid angle (two spherical triangles of its
    // corners, Van Oosterom & Strackee) is 4 pi / n^2.
    auto tri = [](const Vec3d& a, const Vec3d& b, const Vec3d& d) {
        const double num = std::fabs(Dot(a, Cross(b, d)));
        const double den = 1.0 + Dot(a, b) + Dot(b, d) + Dot(d, a);
        return 2.0 * std::atan2(num, den);
    };
    double lo = 1e9, hi = 0.0, sum = 0.0;
    for (int y = 0; y < n; ++y) {
        for (int x = 0; x < n; ++x) {
            const Vec3d a = c.MappedDirection(x, y, n, n), b = c.MappedDirection(x + 1, y, n, n);
            const Vec3d d = c.MappedDirection(x + 1, y + 1, n, n),
                        e = c.MappedDirection(x, y + 1, n, n);
            const double omega = tri(a, b, d) + tri(a, d, e);
            lo = std::min(lo, omega);
            hi = std::max(hi, omega);
            sum += omega;
        }
    }
    const double want = 4.0 * kPi / (n * n);
    EXPECT_NEAR(sum, 4.0 * kPi, 1e-9);
    // Pixels straddling the diamond's fold are bent quads: a few percent.
    EXPECT_GT(lo, 0.9 * want);
    EXPECT_LT(hi, 1.1 * want);
}

TEST(Camera, EquirectHasNoSeam) {
    // The sun due north, on the wrap: the sky is mirror-symmetric about the
    // north-south plane, so column x and column W - 1 - x agree (the wrap's
    // two columns are half a pixel either side of north).
    const Model& m = Prepared("naive", {{"steps", "8"}, {"light-steps", "4"}});
    CameraSpec spec;
    spec.projection = Projection::kEquirect;
    const int w = 64, h = 32;
    const Image image = RenderCustom(m, spec, DirectionFromAzimuthElevation(0.0, 8.0), w, h);
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w / 2; ++x) {
            const Rgb a = image.Get(x, y), b = image.Get(w - 1 - x, y);
            for (int ch = 0; ch < 3; ++ch) {
                EXPECT_NEAR(D(a[ch]), D(b[ch]), 1e-4 * D(std::max(a[ch], b[ch])) + 1e-9)
                    << x << "," << y;
            }
        }
    }
}

// The diffuse horizontal irradiance integrated from an equirect map equals
// bruneton's irradiance table (and the quadrature of its sample).
// At orders=8: the table holds the irradiance of orders 1..N-1 only (Bruneton's 2017 implementation
// notes "Ground irradiance"), so at the default 4 orders it lacks the 4th order's share (blue: 2.1
// % at sun 30 degrees; 0.03 % at 8 orders).
TEST(Camera, HorizontalIrradianceFromTheMapMatchesBrunetonsTable) {
    const Model& m = Prepared("bruneton", {{"orders", "8"}});
    for (double elevation : {30.0, 5.0}) {
        SCOPED_TRACE(elevation);
        CameraSpec spec;
        spec.projection = Projection::kEquirect;
        const int w = 512, h = 256;
        const Image image =
            RenderCustom(m, spec, DirectionFromAzimuthElevation(70.0, elevation), w, h);
        Vec3d map(0.0);
        const double d_az = 2.0 * kPi / w, d_el = kPi / h;
        for (int y = 0; y < h / 2; ++y) {
            const double el = 0.5 * kPi - kPi * (y + 0.5) / h;
            for (int x = 0; x < w; ++x) {
                map += Vec3d(image.Get(x, y)) * (std::sin(el) * std::cos(el) * d_az * d_el);
            }
        }
        const HorizontalIrradiance e = ComputeHorizontalIrradiance(m, Earth(), 0.0, elevation);
        ASSERT_TRUE(e.has_table);
        for (int c = 0; c < 3; ++c) {
            EXPECT_NEAR(map[c], e.diffuse_table[c], 0.01 * e.diffuse_table[c]) << "channel " << c;
            EXPECT_NEAR(map[c], e.diffuse[c], 0.005 * e.diffuse[c]) << "channel " << c;
        }
        // The direct: E T(sun) sin(elevation).
        SampleQuery q;
        q.mu = q.mu_s = std::sin(Radians(elevation));
        const SampleAnswer t = m.Sample({q})[0];
        EXPECT_NEAR(e.direct.x, D(t.transmittance.x) * q.mu, 1e-6);
    }
}

TEST(Camera, SampleSunDiscMatchesARenderedDisc) {
    const Model& m = Prepared("naive", {{"steps", "8"}, {"light-steps", "4"}});
    // A narrow perspective camera centred on the sun.
    CameraSpec spec;
    spec.azimuth_deg = 30.0;
    spec.elevation_deg = 20.0;
    spec.fov_deg = 2.0;
    spec.oriented = true;
    const Vec3d sun = DirectionFromAzimuthElevation(30.0, 20.0);
    const int n = 15;
    const Image image = RenderCustom(m, spec, sun, n, n, true);
    const Camera c = MakeCameraFromSpec(spec, Earth());
    std::vector<SampleQuery> queries;
    for (int y = 0; y < n; ++y) {
        for (int x = 0; x < n; ++x) {
            queries.push_back(QueryFor(c.RayDirection(x, y, n, n), sun, 0.0));
        }
    }
    std::vector<SampleAnswer> answers = m.Sample(queries);
    AddSunDisc(queries, Earth(), &answers);
    int in_disc = 0;
    for (int y = 0; y < n; ++y) {
        for (int x = 0; x < n; ++x) {
            const SampleAnswer& a = answers[static_cast<size_t>(y) * n + x];
            const Rgb p = image.Get(x, y);
            if (p.x > 1000.0f) ++in_disc;
            for (int ch = 0; ch < 3; ++ch) {
                EXPECT_NEAR(D(p[ch]), D(a.radiance[ch]), 1e-4 * D(p[ch]));
            }
        }
    }
    EXPECT_GT(in_disc, 0);
}

TEST(Camera, SpecsAreCheckedWithTheKeyAndRange) {
    auto message = [](auto f) {
        try {
            f();
        } catch (const Error& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    EXPECT_NE(message([] { ParseCameraSpec("altitud=3"); }).find("unknown key 'altitud'"),
              std::string::npos);
    EXPECT_NE(message([] { CheckCameraSpec(ParseCameraSpec("fov=180"), 16, 9); }).find("fov"),
              std::string::npos);
    EXPECT_NE(message([] {
                  CheckCameraSpec(ParseCameraSpec("altitude=-1"), 16, 9);
              }).find("altitude must be >= 0"),
              std::string::npos);
    EXPECT_NE(message([] { ParseCameraSpec("altitude=1km"); }).find("altitude"), std::string::npos);
    EXPECT_NE(message([] {
                  CheckCameraSpec(ParseCameraSpec("projection=equirect"), 64, 64);
              }).find("2:1"),
              std::string::npos);
    EXPECT_NE(
        message([] { CheckCameraSpec(ParseCameraSpec("projection=cubemap"), 64, 64); }).find("6:1"),
        std::string::npos);
    EXPECT_NE(message([] {
                  CheckCameraSpec(ParseCameraSpec("projection=equal-area"), 64, 32);
              }).find("square"),
              std::string::npos);
    EXPECT_NE(message([] {
                  CheckCameraSpec(ParseCameraSpec("projection=equirect,azimuth=3"), 64, 32);
              }).find("world-aligned"),
              std::string::npos);
    EXPECT_NE(message([] { ParseSunSpec("elevation=91"); }).find("[-90, 90]"), std::string::npos);
    EXPECT_NE(message([] { ParseSunSpec("azimuth=10"); }).find("needs elevation"),
              std::string::npos);
    EXPECT_NE(message([] { ParseSunSpec("latitude=1,elevation=3"); }).find("needs time="),
              std::string::npos);
    EXPECT_NE(message([] {
                  ParseSunSpec("time=2024-06-21T12:00Z,latitude=95,longitude=2");
              }).find("latitude"),
              std::string::npos);
    EXPECT_EQ(message([] { CheckCameraSpec(ParseCameraSpec("projection=fisheye,fov=190"), 5, 7); }),
              "no error");
}

// The CLI: bad input is one error line, exit 2, nothing written.
int RunCli(const std::string& args, std::string* err) {
    const char* env = std::getenv("ATMOS_TEST_TMP");
    fs::path dir = (env ? fs::path(env) : fs::temp_directory_path() / "atmos_test") / "camera";
    fs::create_directories(dir);
    const fs::path e = dir / ("err" + std::to_string(getpid()));
    const std::string cmd =
        std::string(ATMOS_CLI_PATH) + " " + args + " > /dev/null 2> " + e.string();
    const int raw = std::system(cmd.c_str());
    std::ifstream f(e);
    std::stringstream ss;
    ss << f.rdbuf();
    *err = ss.str();
    return WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
}

TEST(Camera, CliRefusesBadCamerasAndWritesNothing) {
    const char* env = std::getenv("ATMOS_TEST_TMP");
    const fs::path dir =
        (env ? fs::path(env) : fs::temp_directory_path() / "atmos_test") / "camera";
    fs::create_directories(dir);
    const fs::path out = dir / "bad.exr";
    fs::remove(out);
    const std::string base = "render --model naive -q -o " + out.string() + " ";
    const std::pair<std::string, std::string> cases[] = {
        {"--camera fov=0 --sun elevation=5", "fov"},
        {"--camera fov=180 --sun elevation=5", "fov must be in (0, 180)"},
        {"--camera altitude=-5 --sun elevation=5", "altitude"},
        {"--camera zoom=2 --sun elevation=5", "unknown key 'zoom'"},
        {"--camera projection=equirect --size 64x64 --sun elevation=5", "2:1"},
        {"--camera projection=cubemap --size 64x64 --sun elevation=5", "6:1"},
        {"--camera projection=equal-area --size 64x32 --sun elevation=5", "square"},
        {"--camera projection=orthographic --sun elevation=5", "projection"},
        {"--camera altitude=10", "--sun"},
        {"--camera altitude=10 --sun elevation=100", "elevation"},
        {"--camera altitude=10 --sun elevation=5 --view ground-noon", "--view"},
    };
    for (const auto& [args, needle] : cases) {
        std::string err;
        EXPECT_EQ(RunCli(base + args, &err), 2) << args;
        EXPECT_NE(err.find(needle), std::string::npos) << args << ": " << err;
        EXPECT_EQ(err.rfind("atmos: error: ", 0), 0u) << err;
        EXPECT_FALSE(fs::exists(out)) << args;
    }
    std::string err;
    EXPECT_EQ(RunCli("irradiance --model naive --sun elevation=30,azimuth=400", &err), 2);
    EXPECT_NE(err.find("azimuth"), std::string::npos) << err;
}

}  // namespace

// --sun time=...,latitude=...,longitude=... is the direction of the sun's
// position (NREL SPA, atmos/sun_position.h) at that instant and place, in the
// frame of the camera (+x east, +y north, +z up); a UTC offset is honoured.
TEST(Camera, SunFromADateAndPlaceIsTheSolarPosition) {
    const std::string spec = "time=2024-06-21T14:00:00+02:00,latitude=52.52,longitude=13.405";
    const SunPosition p = SunFromTimeSpec(spec);
    const Vec3d d = ParseSunSpec(spec);
    const double e = p.elevation_deg * kPi / 180.0, a = p.azimuth_deg * kPi / 180.0;
    EXPECT_NEAR(d.x, std::cos(e) * std::sin(a), 1e-12);  // east
    EXPECT_NEAR(d.y, std::cos(e) * std::cos(a), 1e-12);  // north
    EXPECT_NEAR(d.z, std::sin(e), 1e-12);
    // Berlin, two hours after solar noon's UTC 11:00 or so: high in the south-west.
    EXPECT_GT(p.elevation_deg, 50.0);
    EXPECT_GT(p.azimuth_deg, 180.0);
    const Vec3d same = ParseSunSpec("time=2024-06-21T12:00:00Z,latitude=52.52,longitude=13.405");
    EXPECT_NEAR(same.x, d.x, 1e-12);
    EXPECT_NEAR(same.z, d.z, 1e-12);
}
