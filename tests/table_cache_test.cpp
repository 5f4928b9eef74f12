// Issue 33 item 4: the cache of precomputed tables (harness/table_cache.h):
// a second Prepare loads the entry and renders the same bits, a changed
// atmosphere or table-shaping option is a new entry, a damaged entry is
// detected and rebuilt, the size limit evicts the least recently used.
#include <gtest/gtest.h>

#include <stdio.h>
#include <stdlib.h>

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/image.h"
#include "atmos/model.h"
#include "atmos/view.h"
#include "harness/table_cache.h"
#include "test_util.h"

namespace fs = std::filesystem;

namespace atmos {
namespace {

// The whole test binary stays off the user's cache, also when it is run
// without ctest (which sets ATMOS_NO_CACHE=1 too): the CLI tests' commands
// inherit this.
const bool kHermetic = [] { return setenv("ATMOS_NO_CACHE", "1", 1) == 0; }();

using Options = std::map<std::string, std::string>;

// Small tables: the cache does not depend on their size.
const Options kBrunetonSmall = {{"orders", "3"},
                                {"transmittance-width", "32"},
                                {"transmittance-height", "16"},
                                {"irradiance-width", "16"},
                                {"irradiance-height", "8"},
                                {"scattering-r", "8"},
                                {"scattering-mu", "16"},
                                {"scattering-mu-s", "8"},
                                {"scattering-nu", "4"}};

TableCacheSettings Scratch(const std::string& name) {
    const fs::path dir = fs::path(ATMOS_TEST_TMP) / "table_cache" / name;
    fs::remove_all(dir);
    TableCacheSettings s;
    s.directory = dir.string();
    return s;
}

std::vector<float> RenderBits(const Model& model) {
    std::vector<float> all;
    for (const char* view : {"ground-sunrise", "orbit-noon"}) {
        RenderRequest request = atmos_test::QuietRequest(GetView(view, EarthAtmosphere()), 16, 9);
        Image image;
        model.Render(request, &image);
        all.insert(all.end(), image.data(), image.data() + image.size());
    }
    return all;
}

bool SameBits(const std::vector<float>& a, const std::vector<float>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

struct Prepared {
    std::unique_ptr<Model> model;
    TablePrepareResult result;
};

Prepared PrepareCached(const std::string& name, const Options& options,
                       const AtmosphereParameters& atm, const TableCacheSettings& s) {
    Prepared p;
    p.model = CreateModel(name, options);
    p.result = PrepareWithTableCache(p.model.get(), options, atm, s);
    return p;
}

std::vector<float> DirectBits(const std::string& name, const Options& options,
                              const AtmosphereParameters& atm) {
    std::unique_ptr<Model> model = CreateModel(name, options);
    model->Prepare(atm);
    return RenderBits(*model);
}

TEST(TableCache, TheSuiteIsHermetic) {
    ASSERT_TRUE(kHermetic);
    EXPECT_TRUE(UserTableCache().directory.empty());
}

TEST(TableCache, SecondPrepareLoadsTheEntryAndRendersTheSameBits) {
    const AtmosphereParameters atm = EarthAtmosphere();
    for (const auto& [name, options] : std::vector<std::pair<std::string, Options>>{
             {"hillaire", {}}, {"bruneton", kBrunetonSmall}}) {
        SCOPED_TRACE(name);
        const TableCacheSettings s = Scratch("hit_" + name);
        const Prepared first = PrepareCached(name, options, atm, s);
        EXPECT_FALSE(first.result.from_cache);
        EXPECT_TRUE(first.result.stored);
        EXPECT_TRUE(fs::exists(fs::path(first.result.entry) / "manifest.json"));
        const Prepared second = PrepareCached(name, options, atm, s);
        EXPECT_TRUE(second.result.from_cache);
        EXPECT_FALSE(second.result.stored);
        EXPECT_EQ(second.result.entry, first.result.entry);
        // The seconds of the Prepare that computed the tables travel with them.
        EXPECT_EQ(second.result.prepare_seconds, first.result.prepare_seconds);
        const std::vector<float> a = RenderBits(*first.model), b = RenderBits(*second.model);
        EXPECT_TRUE(SameBits(a, b)) << "the loaded tables render other bits";
        EXPECT_TRUE(SameBits(a, DirectBits(name, options, atm)));
    }
}

TEST(TableCache, AnotherAtmosphereOrTableOptionIsANewEntry) {
    const TableCacheSettings s = Scratch("stale");
    const AtmosphereParameters earth = EarthAtmosphere();
    AtmosphereParameters hazy = earth;
    hazy.mie_scattering = hazy.mie_scattering * 2.0;
    hazy.mie_extinction = hazy.mie_extinction * 2.0;
    const Prepared a = PrepareCached("hillaire", {}, earth, s);
    ASSERT_TRUE(a.result.stored);
    // Another atmosphere: rebuilt, and renders as a direct Prepare of it.
    const Prepared b = PrepareCached("hillaire", {}, hazy, s);
    EXPECT_FALSE(b.result.from_cache);
    EXPECT_TRUE(b.result.stored);
    EXPECT_NE(b.result.entry, a.result.entry);
    EXPECT_TRUE(SameBits(RenderBits(*b.model), DirectBits("hillaire", {}, hazy)));
    // A table-shaping option (the option table's ShapesTables rows): rebuilt.
    for (const Options& o :
         {Options{{"transmittance-steps", "20"}}, Options{{"segment-offset", "0.3"}}}) {
        const Prepared c = PrepareCached("hillaire", o, earth, s);
        EXPECT_FALSE(c.result.from_cache) << o.begin()->first;
        EXPECT_TRUE(SameBits(RenderBits(*c.model), DirectBits("hillaire", o, earth)))
            << o.begin()->first;
    }
    // An option that does not shape the tables shares the entry, and the
    // model still renders with its own value (as a direct Prepare).
    const Options march = {{"steps", "13"}};
    const Prepared d = PrepareCached("hillaire", march, earth, s);
    EXPECT_TRUE(d.result.from_cache);
    EXPECT_EQ(d.result.entry, a.result.entry);
    EXPECT_TRUE(SameBits(RenderBits(*d.model), DirectBits("hillaire", march, earth)));
    // The key holds exactly the shaping options.
    EXPECT_EQ(TableCacheKeyText(*d.model, march, earth), TableCacheKeyText(*a.model, {}, earth));
    EXPECT_NE(TableCacheKeyText(*a.model, {{"segment-offset", "0.3"}}, earth),
              TableCacheKeyText(*a.model, {}, earth));
}

TEST(TableCache, ADamagedEntryIsDetectedAndRebuilt) {
    const TableCacheSettings s = Scratch("damaged");
    const AtmosphereParameters atm = EarthAtmosphere();
    const Prepared a = PrepareCached("hillaire", {}, atm, s);
    ASSERT_TRUE(a.result.stored);
    const std::vector<float> want = RenderBits(*a.model);
    // Flip one byte in the middle of each file of the entry in turn (the EXR
    // tables, the JSON, the raw blobs and shaders LoadBaked does not read).
    std::vector<fs::path> tables;
    for (const auto& f : fs::recursive_directory_iterator(a.result.entry)) {
        if (f.is_regular_file() && f.path().filename() != "manifest.json") {
            tables.push_back(f.path());
        }
    }
    ASSERT_GE(tables.size(), 3u);
    for (const fs::path& table : tables) {
        SCOPED_TRACE(table.filename().string());
        {
            std::fstream f(table, std::ios::in | std::ios::out | std::ios::binary);
            f.seekg(0, std::ios::end);
            const std::streamoff middle = f.tellg() / 2;
            f.seekg(middle);
            char c = 0;
            f.read(&c, 1);
            c = static_cast<char>(c ^ 0x5a);
            f.seekp(middle);
            f.write(&c, 1);
        }
        const Prepared b = PrepareCached("hillaire", {}, atm, s);
        EXPECT_FALSE(b.result.from_cache) << "a damaged entry was loaded";
        EXPECT_TRUE(b.result.stored) << "the damaged entry was not rebuilt";
        EXPECT_TRUE(SameBits(RenderBits(*b.model), want));
        const Prepared c = PrepareCached("hillaire", {}, atm, s);
        EXPECT_TRUE(c.result.from_cache) << "the rebuilt entry is not used";
    }
    // A truncated manifest: rebuilt too.
    fs::resize_file(fs::path(a.result.entry) / "manifest.json", 10);
    const Prepared d = PrepareCached("hillaire", {}, atm, s);
    EXPECT_FALSE(d.result.from_cache);
    EXPECT_TRUE(d.result.stored);
}

TEST(TableCache, TheSizeLimitEvictsTheLeastRecentlyUsed) {
    TableCacheSettings s = Scratch("evict");
    const AtmosphereParameters earth = EarthAtmosphere();
    AtmosphereParameters other = earth;
    other.mie_phase_g = 0.7;
    AtmosphereParameters third = earth;
    third.mie_phase_g = 0.6;
    const Prepared a = PrepareCached("hillaire", {}, earth, s);
    const Prepared b = PrepareCached("hillaire", {}, other, s);
    ASSERT_TRUE(a.result.stored && b.result.stored);
    // Use a again (its manifest's time is its last use), then store a third
    // entry with room for about two: b, the least recently used, goes.
    int64_t one = 0;
    for (const auto& f : fs::recursive_directory_iterator(a.result.entry)) {
        if (f.is_regular_file()) one += static_cast<int64_t>(f.file_size());
    }
    fs::last_write_time(fs::path(b.result.entry) / "manifest.json",
                        fs::file_time_type::clock::now() - std::chrono::minutes(5));
    EXPECT_TRUE(PrepareCached("hillaire", {}, earth, s).result.from_cache);
    s.max_bytes = 2 * one + one / 2;
    const Prepared c = PrepareCached("hillaire", {}, third, s);
    EXPECT_TRUE(c.result.stored);
    EXPECT_TRUE(fs::exists(a.result.entry));
    EXPECT_FALSE(fs::exists(b.result.entry));
    EXPECT_TRUE(fs::exists(c.result.entry));
}

TEST(TableCache, UserSettingsFollowTheEnvironment) {
    const char* saved = std::getenv("XDG_CACHE_HOME");
    const std::string saved_text = saved ? saved : "";
    setenv("ATMOS_NO_CACHE", "0", 1);
    setenv("XDG_CACHE_HOME", "/tmp/atmos-xdg", 1);
    EXPECT_EQ(UserTableCache().directory, "/tmp/atmos-xdg/atmos/tables");
    EXPECT_TRUE(UserTableCache(true).directory.empty());  // --no-cache
    setenv("ATMOS_CACHE_MAX_MB", "3", 1);
    EXPECT_EQ(UserTableCache().max_bytes, int64_t{3} << 20);
    unsetenv("ATMOS_CACHE_MAX_MB");
    setenv("ATMOS_NO_CACHE", "1", 1);
    EXPECT_TRUE(UserTableCache().directory.empty());
    if (saved) {
        setenv("XDG_CACHE_HOME", saved_text.c_str(), 1);
    } else {
        unsetenv("XDG_CACHE_HOME");
    }
}

std::string ReadAll(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// The CLI prepares through the cache (a second render loads the entry, the
// same bytes); --no-cache neither reads nor writes it.
TEST(TableCacheCli, RenderTwiceLoadsTheEntryAndNoCacheSkipsIt) {
    const fs::path dir = fs::path(ATMOS_TEST_TMP) / "table_cache" / "cli";
    fs::remove_all(dir);
    fs::create_directories(dir);
    const std::string env = "ATMOS_NO_CACHE=0 XDG_CACHE_HOME=" + (dir / "xdg").string() + " ";
    const std::string render =
        env + ATMOS_CLI_PATH + " render --model hillaire --view plane-sunrise --size 24x14 -o ";
    auto run = [&](const std::string& out, const std::string& extra) {
        const std::string log = (dir / (out + ".log")).string();
        EXPECT_EQ(std::system((render + (dir / out).string() + extra + " 2>" + log).c_str()), 0);
        return ReadAll(log);
    };
    EXPECT_EQ(run("a.npy", "").find("from the cache"), std::string::npos);
    EXPECT_NE(run("b.npy", "").find("from the cache"), std::string::npos);
    EXPECT_EQ(run("c.npy", " --no-cache").find("from the cache"), std::string::npos);
    const std::string a = ReadAll(dir / "a.npy");
    EXPECT_FALSE(a.empty());
    EXPECT_EQ(a, ReadAll(dir / "b.npy"));
    EXPECT_EQ(a, ReadAll(dir / "c.npy"));
    int entries = 0;
    for (const auto& e : fs::directory_iterator(dir / "xdg" / "atmos" / "tables")) {
        entries += e.path().filename().string().rfind("hillaire-", 0) == 0;
    }
    EXPECT_EQ(entries, 1);
}

// Issue 33 item 5: `viewer --load DIR` (and `bake --load DIR`) take the model
// and its options from the bake's JSON; bake's default model bakes.
TEST(TableCacheCli, LoadTakesTheModelFromTheBake) {
    const fs::path dir = fs::path(ATMOS_TEST_TMP) / "table_cache" / "load";
    fs::remove_all(dir);
    fs::create_directories(dir);
    const std::string cli = std::string(ATMOS_CLI_PATH) + " ";
    const std::string quiet = " -q 2>/dev/null";
    const std::string bake = (dir / "bake").string();
    ASSERT_EQ(
        std::system(
            (cli + "bake --model hillaire:transmittance-steps=20 -o " + bake + quiet).c_str()),
        0);
    EXPECT_EQ(
        std::system(
            (cli + "viewer --load " + bake + " -o " + (dir / "viewer").string() + quiet).c_str()),
        0);
    EXPECT_TRUE(fs::exists(dir / "viewer" / "hillaire" / "hillaire.json"));
    EXPECT_EQ(
        std::system(
            (cli + "bake --load " + bake + " -o " + (dir / "again").string() + quiet).c_str()),
        0);
    EXPECT_TRUE(fs::exists(dir / "again" / "hillaire.json"));
    // Not a bake: one error, exit 2.
    EXPECT_NE(std::system((cli + "viewer --load " + (dir / "viewer").string() + " -o " +
                           (dir / "none").string() + quiet)
                              .c_str()),
              0);
    // The default model of bake is one that bakes.
    FILE* help = popen((cli + "bake --help").c_str(), "r");
    ASSERT_NE(help, nullptr);
    std::string text;
    char buffer[4096];
    while (size_t n = fread(buffer, 1, sizeof(buffer), help)) text.append(buffer, n);
    pclose(help);
    EXPECT_NE(text.find("--model TEXT=bruneton"), std::string::npos);
}

}  // namespace
}  // namespace atmos
