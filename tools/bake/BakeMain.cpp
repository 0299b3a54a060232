// cairn-bake: bakes whole levels (OBJ) into a tiled Detour navmesh file in Recast's demo layout, with the
// runtime's pipeline on all cores; `merge` combines the outputs of shards (--shard K/N) into one file.
// Flags with CLI11 (Debian's libcli11-dev). Errors: one line naming the file and what is wrong, exit code 1,
// no partial output (files are written to a temporary name and renamed).

#include "BakeConfig.h"
#include "Baker.h"
#include "OffMeshLinksFile.h"
#include "OutputPaths.h"
#include "cairn/navmesh/NavMeshFile.h"
#include "cairn/navmesh/NavMeshPreview.h"
#include "cairn/navmesh/PendingFile.h"

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <optional>
#include <string>
#include <unistd.h>

using namespace cairn;
using namespace cairn::physics;

namespace
{
/// Commits every output (each complete under its temporary name) in turn: the new navmesh never stands
/// beside a failed summary or preview.
Status CommitAll(std::vector<navmesh::PendingFile*> inFiles, navmesh::NavMeshFileWriter* inNavMesh)
{
    if (inNavMesh != nullptr)
        if (Status committed = inNavMesh->Commit(); !committed) return committed;
    for (navmesh::PendingFile* file : inFiles)
        if (Status committed = file->Commit(); !committed) return committed;
    return Status::Ok();
}

int Fail(const std::string& inMessage)
{
    std::fprintf(stderr, "cairn-bake: %s\n", inMessage.c_str());
    return 1;
}
} // namespace

int main(int argc, char** argv)
{
    // SIGINT and SIGTERM (a cancelled build-farm job) leave no temporary output behind
    navmesh::RemovePendingFilesOnTermination();
    CLI::App app{"cairn-bake: bake level meshes into a tiled Detour navmesh (Recast's saved-navmesh layout)"};
    app.require_subcommand(1);

    bake::BakeSettings settings;
    std::string output, shard = "0/1";
    CLI::App* bakeCommand = app.add_subcommand("bake", "Bake OBJ and glTF level files");
    bakeCommand
        ->add_option("inputs", settings.mInputs,
                     "OBJ and glTF files (.obj, .gltf, .glb; each object a static mesh)")
        ->required();
    bakeCommand->add_option("-o,--output", output, "The navmesh file to write")->required();
    bakeCommand->add_option("--threads", settings.mThreads, "Threads (0: all cores)")
        ->check(CLI::Range(0, 256));
    bakeCommand->add_option("--shard", shard, "Bake shard K of N (K/N, K from 0)");
    std::vector<float> box;
    bakeCommand->add_option("--box", box, "Only the tiles overlapping this box: MINX,MINZ,MAXX,MAXZ (m)")
        ->expected(4)
        ->delimiter(',');
    std::vector<std::string> tileTexts;
    bakeCommand->add_option("--tile", tileTexts, "Only this tile, X,Z (repeat for more)");
    std::string summaryPath, previousSummaryPath, previousNavMeshPath;
    bakeCommand->add_option("--summary", summaryPath,
                            "Write a JSON summary (tiles, polygons, per-tile hashes)");
    bakeCommand->add_option("--previous", previousSummaryPath,
                            "Incremental: the previous bake's summary (with --previous-navmesh)");
    bakeCommand->add_option("--previous-navmesh", previousNavMeshPath,
                            "Incremental: the previous bake's navmesh");
    // Flags override the JSON config: they go to a profile of their own, copied over the config's when given
    navmesh::AgentProfile flagProfile;
    std::string configPath;
    bakeCommand->add_option("--config", configPath, "Agent profile and tile size from a JSON file");
    std::string areasPath, linksPath, previewObjPath, previewSvgPath;
    bakeCommand->add_option("--preview-obj", previewObjPath,
                            "Also write the navmesh's walkable surface as Wavefront OBJ");
    bakeCommand->add_option("--preview-svg", previewSvgPath,
                            "Also write a top-down SVG map of the navmesh (areas, tiles, links)");
    bakeCommand->add_option("--areas", areasPath,
                            "Navmesh area ids of material names, from a JSON file "
                            "({\"default\": 0, \"materials\": {\"road\": 1}})");
    bakeCommand->add_option(
        "--links", linksPath,
        "Off-mesh links (jumps, drops, ladders) from a JSON file "
        "({\"links\": [{\"start\": [x, y, z], \"end\": [x, y, z]}]}, see docs/BAKING.md)");
    navmesh::LevelLoadLimits& limits = settings.mLoadLimits;
    bakeCommand->add_flag("--allow-outside-files", limits.mAllowFilesOutsideFolder,
                          "glTF buffers may come from outside the level file's folder");
    bakeCommand
        ->add_option("--max-file-bytes", limits.mMaxFileBytes, "Largest level file (and glTF buffer file)")
        ->check(CLI::PositiveNumber);
    bakeCommand->add_option("--max-triangles", limits.mMaxTriangles, "Most triangles per level file")
        ->check(CLI::PositiveNumber);
    bakeCommand->add_option("--max-vertices", limits.mMaxVertices, "Most vertices per level file")
        ->check(CLI::PositiveNumber);
    // Bounded: tinygltf's JSON conversion recurses, a level per nesting
    bakeCommand->add_option("--max-nesting", limits.mMaxNesting, "Deepest JSON nesting of a glTF")
        ->check(CLI::Range(1, 1000));
    bakeCommand->add_option("--max-node-depth", limits.mMaxNodeDepth, "Deepest glTF node tree")
        ->check(CLI::Range(1, 100000));
    CLI::Option* flags[] = {
        bakeCommand->add_option("--tile-size", flagProfile.mTileSize, "Tile side, m"),
        bakeCommand->add_option("--cell-size", flagProfile.mCellSize, "Voxel size, m"),
        bakeCommand->add_option("--cell-height", flagProfile.mCellHeight, "Voxel height, m"),
        bakeCommand->add_option("--agent-height", flagProfile.mHeight, "m"),
        bakeCommand->add_option("--agent-radius", flagProfile.mRadius, "m"),
        bakeCommand->add_option("--agent-max-climb", flagProfile.mMaxClimb, "m"),
        bakeCommand->add_option("--agent-max-slope", flagProfile.mMaxSlopeDegrees, "degrees"),
    };
    float navmesh::AgentProfile::*fields[] = {
        &navmesh::AgentProfile::mTileSize,        &navmesh::AgentProfile::mCellSize,
        &navmesh::AgentProfile::mCellHeight,      &navmesh::AgentProfile::mHeight,
        &navmesh::AgentProfile::mRadius,          &navmesh::AgentProfile::mMaxClimb,
        &navmesh::AgentProfile::mMaxSlopeDegrees,
    };

    std::vector<std::string> shards;
    std::string mergedOutput;
    CLI::App* mergeCommand = app.add_subcommand("merge", "Combine shard outputs into one navmesh file");
    mergeCommand->add_option("shards", shards, "Navmesh files of the shards")->required();
    mergeCommand->add_option("-o,--output", mergedOutput, "The navmesh file to write")->required();
    std::string mergeLinksPath;
    mergeCommand->add_option("--links", mergeLinksPath,
                             "The shards' links file: then a link the tile builder left out is reported too");
    std::vector<std::string> shardSummaries;
    mergeCommand->add_option(
        "--summary", shardSummaries,
        "Each shard's summary, in the order of the shards: then a missing shard is an error");

    try
    {
        app.parse(argc, argv);
    }
    catch (const CLI::ParseError& error)
    {
        // CLI11 prints the help or the message; a usage error exits with 1, as every other error
        return app.exit(error) == 0 ? 0 : 1;
    }

    if (*mergeCommand)
    {
        std::vector<bake::NamedPath> shardInputs;
        for (const std::string& path : shards)
            shardInputs.push_back({"shard", path});
        for (const std::string& path : shardSummaries)
            shardInputs.push_back({"--summary", path});
        if (!mergeLinksPath.empty()) shardInputs.push_back({"--links", mergeLinksPath});
        if (Status usable = bake::CheckOutputPaths({{"-o", mergedOutput}}, shardInputs); !usable)
            return Fail(usable.GetError().mMessage);
        std::vector<navmesh::NavMeshFileContents> loaded;
        for (const std::string& path : shards)
        {
            Result<navmesh::NavMeshFileContents> contents = navmesh::LoadNavMeshFile(path);
            if (!contents) return Fail(contents.GetError().mMessage);
            loaded.push_back(std::move(contents.Value()));
        }
        if (shardSummaries.empty())
            std::fprintf(stderr,
                         "cairn-bake: merge: without each shard's --summary, a missing shard cannot be "
                         "noticed\n");
        else
        {
            std::vector<bake::BakeSummary> summaries;
            for (const std::string& path : shardSummaries)
            {
                Result<bake::BakeSummary> summary = bake::LoadBakeSummary(path);
                if (!summary) return Fail(summary.GetError().mMessage);
                summaries.push_back(std::move(summary.Value()));
            }
            if (Status complete = bake::CheckShardsComplete(summaries, loaded); !complete)
                return Fail(complete.GetError().mMessage);
        }
        Result<navmesh::NavMeshFileContents> merged = bake::MergeShards(loaded);
        if (!merged) return Fail(merged.GetError().mMessage);
        std::vector<navmesh::OffMeshLink> declared;
        if (!mergeLinksPath.empty())
        {
            Result<std::vector<navmesh::OffMeshLink>> links = bake::LoadOffMeshLinks(mergeLinksPath);
            if (!links) return Fail(links.GetError().mMessage);
            declared = std::move(links.Value());
        }
        Result<std::vector<bake::UnjoinedLink>> unjoined = bake::FindUnjoinedLinks(merged.Value(), declared);
        if (!unjoined) return Fail(unjoined.GetError().mMessage);
        for (const bake::UnjoinedLink& link : unjoined.Value())
            std::fprintf(stderr, "cairn-bake: warning: %s\n", bake::DescribeUnjoinedLink(link).c_str());
        if (Status saved = navmesh::SaveNavMeshFile(mergedOutput, merged.Value()); !saved)
            return Fail(saved.GetError().mMessage);
        std::printf("merged %zu shards: %zu tiles -> %s\n", shards.size(), merged.Value().mTiles.size(),
                    mergedOutput.c_str());
        return 0;
    }

    // Outputs checked before any work: an unusable one was reported only after the whole bake
    std::vector<bake::NamedPath> outputs{{"-o", output}};
    for (const bake::NamedPath& optional :
         {bake::NamedPath{"--summary", summaryPath}, bake::NamedPath{"--preview-obj", previewObjPath},
          bake::NamedPath{"--preview-svg", previewSvgPath}})
        if (!optional.mPath.empty()) outputs.push_back(optional);
    std::vector<bake::NamedPath> inputs{{"--config", configPath},
                                        {"--areas", areasPath},
                                        {"--links", linksPath},
                                        {"--previous", previousSummaryPath},
                                        {"--previous-navmesh", previousNavMeshPath}};
    for (const std::string& path : settings.mInputs)
        inputs.push_back({"input", path});
    if (Status usable = bake::CheckOutputPaths(outputs, inputs); !usable)
        return Fail(usable.GetError().mMessage);

    if (!configPath.empty())
        if (Status loaded = bake::LoadBakeConfig(configPath, settings.mProfile); !loaded)
            return Fail(loaded.GetError().mMessage);
    if (!areasPath.empty())
    {
        Result<navmesh::AreaMapping> areas = bake::LoadAreaMapping(areasPath);
        if (!areas) return Fail(areas.GetError().mMessage);
        settings.mAreas = std::move(areas.Value());
    }
    if (!linksPath.empty())
    {
        Result<std::vector<navmesh::OffMeshLink>> links = bake::LoadOffMeshLinks(linksPath);
        if (!links) return Fail(links.GetError().mMessage);
        settings.mLinks = std::move(links.Value());
    }
    for (size_t i = 0; i < std::size(flags); ++i)
        if (flags[i]->count() > 0) settings.mProfile.*fields[i] = flagProfile.*fields[i];
    if (!box.empty())
    {
        if (box.size() != 4) return Fail("--box: expected MINX,MINZ,MAXX,MAXZ");
        settings.mRegion =
            AABB(Vec3(box[0], -cMaxWorldCoordinate, box[1]), Vec3(box[2], cMaxWorldCoordinate, box[3]));
    }
    for (const std::string& text : tileTexts)
    {
        int x = 0, z = 0;
        char extra = 0;
        if (std::sscanf(text.c_str(), "%d,%d%c", &x, &z, &extra) != 2)
            return Fail("--tile " + text + ": expected X,Z (whole numbers)");
        settings.mTiles.push_back({x, z});
    }
    if (!bake::ParseShard(shard, settings.mShard, settings.mShardCount))
        return Fail("--shard " + shard + ": expected K/N with 0 <= K < N");
    // A bar on a terminal, a line every tenth otherwise (logs)
    const bool terminal = isatty(fileno(stdout)) != 0;
    const auto start = std::chrono::steady_clock::now();
    uint32_t lastTenth = 0;
    settings.mProgress = [&](uint32_t inDone, uint32_t inTotal)
    {
        const double seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        const double rate = seconds > 0.0 ? inDone / seconds : 0.0;
        const double eta = rate > 0.0 ? (inTotal - inDone) / rate : 0.0;
        if (terminal)
        {
            std::printf("\r  tiles %u/%u  %.1f tiles/s  ETA %.0f s   ", inDone, inTotal, rate, eta);
            std::fflush(stdout);
        }
        else if (const uint32_t tenth = inDone * 10 / std::max(inTotal, 1u);
                 tenth > lastTenth || inDone == inTotal)
        {
            lastTenth = tenth;
            std::printf("tiles %u/%u (%.1f tiles/s, ETA %.0f s)\n", inDone, inTotal, rate, eta);
        }
    };
    std::optional<bake::BakeSummary> previous;
    std::optional<navmesh::NavMeshFileContents> previousNavMesh;
    if (previousSummaryPath.empty() != previousNavMeshPath.empty())
        return Fail("--previous and --previous-navmesh go together");
    if (!previousSummaryPath.empty())
    {
        Result<bake::BakeSummary> loadedSummary = bake::LoadBakeSummary(previousSummaryPath);
        if (!loadedSummary) return Fail(loadedSummary.GetError().mMessage);
        Result<navmesh::NavMeshFileContents> loadedNavMesh = navmesh::LoadNavMeshFile(previousNavMeshPath);
        if (!loadedNavMesh) return Fail(loadedNavMesh.GetError().mMessage);
        previous = std::move(loadedSummary.Value());
        previousNavMesh = std::move(loadedNavMesh.Value());
        settings.mPrevious = &*previous;
        settings.mPreviousNavMesh = &*previousNavMesh;
    }
    settings.mOutputPath = output;  // Tiles go to the file as they are done
    settings.mCommitOutput = false; // In place with the other outputs, or not at all
    Result<bake::BakeResult> result = bake::Bake(settings);
    if (terminal) std::printf("\n");
    if (!result) return Fail(result.GetError().mMessage);
    // Every output complete under its temporary name before any is renamed into place
    std::optional<navmesh::PendingFile> summaryFile, previewObjFile, previewSvgFile;
    auto write = [](std::optional<navmesh::PendingFile>& outFile, const std::string& inPath,
                    const std::string& inText) -> Status
    {
        outFile.emplace(inPath);
        if (Status opened = outFile->GetOpenStatus(); !opened) return opened;
        outFile->Stream() << inText;
        return outFile->Complete();
    };
    if (!summaryPath.empty())
        if (Status written =
                write(summaryFile, summaryPath, bake::BakeSummaryToJson(result.Value().mSummary));
            !written)
            return Fail(written.GetError().mMessage);
    if (!previewObjPath.empty() || !previewSvgPath.empty())
    {
        // The previews show the file as a runtime loads it
        Result<navmesh::NavMeshFileContents> written =
            navmesh::LoadNavMeshFile(result.Value().mOutput->GetTemporaryPath());
        if (!written) return Fail(written.GetError().mMessage);
        Result<navmesh::DetourNavMeshPtr> navMesh = navmesh::CreateDetourNavMesh(written.Value());
        if (!navMesh) return Fail(navMesh.GetError().mMessage);
        if (!previewObjPath.empty())
            if (Status saved = write(previewObjFile, previewObjPath, navmesh::NavMeshToObj(*navMesh.Value()));
                !saved)
                return Fail(saved.GetError().mMessage);
        if (!previewSvgPath.empty())
            if (Status saved = write(previewSvgFile, previewSvgPath, navmesh::NavMeshToSvg(*navMesh.Value()));
                !saved)
                return Fail(saved.GetError().mMessage);
    }
    std::vector<navmesh::PendingFile*> pending;
    for (std::optional<navmesh::PendingFile>* file : {&summaryFile, &previewObjFile, &previewSvgFile})
        if (file->has_value()) pending.push_back(&**file);
    if (Status committed = CommitAll(pending, result.Value().mOutput.get()); !committed)
        return Fail(committed.GetError().mMessage);
    const bake::BakeResult& baked = result.Value();
    std::printf("%llu bodies (at most %u at once); rebuilt %u, baked %u of %u tiles (shard %u/%u), %u with "
                "polygons, %llu polygons, in %.1f ms (load %.1f ms) -> %s\n",
                (unsigned long long)baked.mBodies, baked.mPeakBodies, baked.mSummary.mTilesRebuilt,
                baked.mTilesBaked, baked.mTilesInWorld, settings.mShard, settings.mShardCount,
                baked.mTilesWithPolygons, (unsigned long long)baked.mPolygons, baked.mBakeMs, baked.mLoadMs,
                output.c_str());
    if (!settings.mLinks.empty())
    {
        for (const bake::UnjoinedLink& link : baked.mUnjoinedLinks)
            std::fprintf(stderr, "cairn-bake: warning: %s\n", bake::DescribeUnjoinedLink(link).c_str());
        if (baked.mLinksChecked)
            std::printf("off-mesh links: %zu, %zu that no agent can take\n", settings.mLinks.size(),
                        baked.mUnjoinedLinks.size());
        else
            std::printf("off-mesh links: %zu, not checked (a part of the level: the merge checks them)\n",
                        settings.mLinks.size());
    }
    return 0;
}
