// Off-mesh links in a bake: a link from the links file joins two platforms a gap apart in the baked navmesh
// (a path crosses it, with the link's user id and area kept, one way only for a drop); an incremental bake
// builds again the tile whose link changed and only that one; the links file's errors name the file, the
// link and the key, and a link with an end in no tile of the level is refused; a link Detour leaves unjoined
// is reported, by the bake of a whole level and by the merge of shards.

#include "Baker.h"
#include "OffMeshLinksFile.h"
#include "cairn/navmesh/NavMeshFile.h"
#include "common/TempFiles.h"

#include <DetourNavMesh.h>
#include <DetourNavMeshQuery.h>
#include <gtest/gtest.h>

namespace cairn::bake
{
using namespace cairn::physics;
namespace
{

/// Two floors a 3 m gap apart along x (x in [0, 10] and [13, 24], z in [0, 8]), both in tile (0, 0) and the
/// second also in tile (1, 0) of the 12.8 m grid.
const char* cTwoPlatforms = "v 0 0 0\nv 10 0 0\nv 10 0 8\nv 0 0 8\n"
                            "v 13 0 0\nv 24 0 0\nv 24 0 8\nv 13 0 8\n"
                            "o West\nf 1 4 3\nf 1 3 2\no East\nf 5 8 7\nf 5 7 6\n";

const char* cJump = R"({"links": [{"start": [9, 0, 4], "end": [14, 0, 4], "radius": 0.6, "area": 3,
                                   "user_id": 42, "bidirectional": false}]})";

class BakeLinksTest : public ::testing::Test
{
protected:
    std::string Write(const std::string& inName, const std::string& inText)
    {
        return mFiles.Write(inName, inText);
    }

    Result<BakeResult> BakeWith(const std::string& inLinks, const BakeSummary* inPrevious = nullptr,
                                const navmesh::NavMeshFileContents* inPreviousNavMesh = nullptr,
                                const std::string& inLevel = cTwoPlatforms)
    {
        BakeSettings settings;
        settings.mInputs = {Write("platforms.obj", inLevel)};
        settings.mThreads = 1;
        settings.mPrevious = inPrevious;
        settings.mPreviousNavMesh = inPreviousNavMesh;
        if (!inLinks.empty())
        {
            Result<std::vector<navmesh::OffMeshLink>> links = LoadOffMeshLinks(Write("links.json", inLinks));
            if (!links) return links.GetError();
            settings.mLinks = links.Value();
        }
        return Bake(settings);
    }

    /// Whether Detour finds a whole path on inContents from inFrom to inTo (the default filter).
    static bool Reaches(const navmesh::NavMeshFileContents& inContents, const Vec3& inFrom, const Vec3& inTo)
    {
        Result<navmesh::DetourNavMeshPtr> navMesh = navmesh::CreateDetourNavMesh(inContents);
        EXPECT_TRUE(navMesh);
        if (!navMesh) return false;
        dtNavMeshQuery query;
        EXPECT_TRUE(dtStatusSucceed(query.init(navMesh.Value().get(), 2048)));
        const dtQueryFilter filter;
        const float extent[3] = {1, 2, 1};
        dtPolyRef from = 0, to = 0;
        float fromPoint[3], toPoint[3];
        query.findNearestPoly(inFrom.data(), extent, &filter, &from, fromPoint);
        query.findNearestPoly(inTo.data(), extent, &filter, &to, toPoint);
        EXPECT_NE(from, 0u);
        EXPECT_NE(to, 0u);
        dtPolyRef path[256];
        int count = 0;
        query.findPath(from, to, fromPoint, toPoint, &filter, path, &count, 256);
        return count > 0 && path[count - 1] == to;
    }

    /// The off-mesh connections in inContents' tiles, each with its polygon's area.
    static std::vector<std::pair<dtOffMeshConnection, int>>
    Links(const navmesh::NavMeshFileContents& inContents)
    {
        std::vector<std::pair<dtOffMeshConnection, int>> links;
        Result<navmesh::DetourNavMeshPtr> navMesh = navmesh::CreateDetourNavMesh(inContents);
        if (!navMesh) return links;
        const dtNavMesh& mesh = *navMesh.Value();
        for (int i = 0; i < mesh.getMaxTiles(); ++i)
            if (const dtMeshTile* tile = mesh.getTile(i); tile != nullptr && tile->header != nullptr)
                for (int c = 0; c < tile->header->offMeshConCount; ++c)
                    links.push_back({tile->offMeshCons[c], tile->polys[tile->offMeshCons[c].poly].getArea()});
        return links;
    }

    cairn::test::TempFiles mFiles;
};

TEST_F(BakeLinksTest, ALinkJoinsPlatformsAGapApart)
{
    const Vec3 west(3, 0, 4), east(20, 0, 4);
    Result<BakeResult> apart = BakeWith("");
    ASSERT_TRUE(apart) << apart.GetError().mMessage;
    EXPECT_FALSE(Reaches(apart.Value().mNavMesh, west, east));
    EXPECT_TRUE(Links(apart.Value().mNavMesh).empty());

    Result<BakeResult> joined = BakeWith(cJump);
    ASSERT_TRUE(joined) << joined.GetError().mMessage;
    EXPECT_TRUE(Reaches(joined.Value().mNavMesh, west, east));
    EXPECT_FALSE(Reaches(joined.Value().mNavMesh, east, west)) << "a drop, one way";
    const std::vector<std::pair<dtOffMeshConnection, int>> links = Links(joined.Value().mNavMesh);
    ASSERT_EQ(links.size(), 1u);
    EXPECT_EQ(links[0].first.userId, 42u);
    EXPECT_EQ(links[0].second, 3);
    EXPECT_NEAR(links[0].first.pos[0], 9.0f, 0.01f);
    EXPECT_NEAR(links[0].first.pos[3], 14.0f, 0.01f);
    EXPECT_NEAR(links[0].first.rad, 0.6f, 1e-6f);
}

// An incremental bake after the link moved builds again the tile of its start (the link is in that tile's
// data) and takes the other tile over; the result is the full bake's
TEST_F(BakeLinksTest, AMovedLinkRebuildsItsTileOnly)
{
    Result<BakeResult> first = BakeWith(cJump);
    ASSERT_TRUE(first) << first.GetError().mMessage;
    ASSERT_EQ(first.Value().mSummary.mTiles.size(), 2u);
    // Only the start's z changes
    const std::string moved = R"({"links": [{"start": [9, 0, 5], "end": [14, 0, 4], "radius": 0.6, "area": 3,
                                             "user_id": 42, "bidirectional": false}]})";
    Result<BakeResult> again = BakeWith(moved, &first.Value().mSummary, &first.Value().mNavMesh);
    ASSERT_TRUE(again) << again.GetError().mMessage;
    EXPECT_EQ(again.Value().mSummary.mTilesRebuilt, 1u);
    Result<BakeResult> full = BakeWith(moved);
    ASSERT_TRUE(full);
    ASSERT_EQ(again.Value().mNavMesh.mTiles.size(), full.Value().mNavMesh.mTiles.size());
    for (size_t i = 0; i < full.Value().mNavMesh.mTiles.size(); ++i)
        EXPECT_EQ(again.Value().mNavMesh.mTiles[i].mData, full.Value().mNavMesh.mTiles[i].mData) << i;
    Result<BakeResult> same = BakeWith(moved, &full.Value().mSummary, &full.Value().mNavMesh);
    ASSERT_TRUE(same);
    EXPECT_EQ(same.Value().mSummary.mTilesRebuilt, 0u) << "nothing changed";
}

// Links that could never join the navmesh are refused: an end in no tile of the level, an end more than a
// tile from its start's (Detour joins ends in the start's tile and the eight around it only), a start in a
// tile of the level that has no navmesh
TEST_F(BakeLinksTest, LinksThatCouldNeverJoinAreRefused)
{
    const auto refusal = [&](const std::string& inLinks)
    {
        Result<BakeResult> baked = BakeWith(inLinks);
        return baked ? std::string("baked") : baked.GetError().mMessage;
    };
    EXPECT_NE(
        refusal(R"({"links": [{"start": [9, 0, 4], "end": [9, 0, 40]}]})").find("off-mesh link 0: its end"),
        std::string::npos);
    EXPECT_NE(
        refusal(
            R"({"links": [{"start": [1, 0, 1], "end": [2, 0, 2]}, {"start": [9, 0, 4], "end": [30, 0, 4]}]})")
            .find("off-mesh link 1: its end is more than a tile from its start's"),
        std::string::npos);
    // The level's bounds reach z = 8 from x = 0 to 24 only; (20, 0, 6) is on the east platform
    EXPECT_EQ(refusal(R"({"links": [{"start": [9, 0, 4], "end": [20, 0, 6]}]})"), "baked");
    // A wall at z = 20 makes tile (0, 1) the level's, with nothing to walk on
    const std::string withWall =
        std::string(cTwoPlatforms) + "v 2 0 20\nv 4 0 20\nv 4 3 20\nv 2 3 20\no Wall\nf 9 10 11\nf 9 11 12\n";
    Result<BakeResult> walled =
        BakeWith(R"({"links": [{"start": [3, 0, 15], "end": [3, 0, 6]}]})", nullptr, nullptr, withWall);
    ASSERT_FALSE(walled);
    EXPECT_NE(walled.GetError().mMessage.find("has no navmesh for the off-mesh links"), std::string::npos)
        << walled.GetError().mMessage;
}

// Links no agent can take are reported: an end over the gap and an end 2 m above the floor (past the climb),
// which Detour leaves unjoined, and a start 3 m in the air, which its tile builder leaves out. A joined link
// whose end is in the next tile is not. A shard leaves the check to the merge, which finds the same
TEST_F(BakeLinksTest, LinksNoAgentCanTakeAreReported)
{
    const std::string links = R"({"links": [
        {"start": [9, 0, 4], "end": [14, 0, 4], "radius": 0.6, "user_id": 1},
        {"start": [9, 0, 2], "end": [11.5, 0, 2], "radius": 0.5, "user_id": 2},
        {"start": [9, 0, 6], "end": [20, 2, 6], "radius": 0.6, "user_id": 3},
        {"start": [5, 3, 4], "end": [14, 0, 5], "radius": 0.6, "user_id": 4}]})";
    Result<BakeResult> baked = BakeWith(links);
    ASSERT_TRUE(baked) << baked.GetError().mMessage;
    ASSERT_TRUE(baked.Value().mLinksChecked);
    const std::vector<UnjoinedLink>& unjoined = baked.Value().mUnjoinedLinks;
    ASSERT_EQ(unjoined.size(), 3u);
    EXPECT_EQ(unjoined[0].mUserID, 2u);
    EXPECT_EQ(unjoined[1].mUserID, 3u);
    EXPECT_EQ(unjoined[2].mUserID, 4u);
    for (int i : {0, 1})
    {
        EXPECT_TRUE(unjoined[size_t(i)].mStartJoined) << i;
        EXPECT_FALSE(unjoined[size_t(i)].mEndJoined) << i;
        EXPECT_NE(DescribeUnjoinedLink(unjoined[size_t(i)]).find("its end joins no navmesh"),
                  std::string::npos);
    }
    EXPECT_FALSE(unjoined[2].mBuilt);
    EXPECT_NE(DescribeUnjoinedLink(unjoined[2]).find("is not in the navmesh"), std::string::npos);
    EXPECT_NE(DescribeUnjoinedLink(unjoined[2]).find("(5.00, 3.00, 4.00)"), std::string::npos);
    EXPECT_EQ(Links(baked.Value().mNavMesh).size(), 3u) << "the builder left the fourth out";
    EXPECT_TRUE(Reaches(baked.Value().mNavMesh, Vec3(3, 0, 4), Vec3(20, 0, 4))) << "link 1 joins";

    // Two shards: each bakes part of the level and checks nothing; their merge is checked as the whole
    std::vector<navmesh::NavMeshFileContents> shards;
    for (uint32_t shard = 0; shard < 2; ++shard)
    {
        BakeSettings settings;
        settings.mInputs = {Write("platforms.obj", cTwoPlatforms)};
        settings.mThreads = 1;
        settings.mLinks = LoadOffMeshLinks(Write("links.json", links)).Value();
        settings.mShard = shard;
        settings.mShardCount = 2;
        Result<BakeResult> part = Bake(settings);
        ASSERT_TRUE(part) << part.GetError().mMessage;
        EXPECT_FALSE(part.Value().mLinksChecked);
        EXPECT_TRUE(part.Value().mUnjoinedLinks.empty());
        shards.push_back(std::move(part.Value().mNavMesh));
    }
    Result<navmesh::NavMeshFileContents> merged = MergeShards(shards);
    ASSERT_TRUE(merged) << merged.GetError().mMessage;
    const std::vector<navmesh::OffMeshLink> declared = LoadOffMeshLinks(Write("links.json", links)).Value();
    Result<std::vector<UnjoinedLink>> again = FindUnjoinedLinks(merged.Value(), declared);
    ASSERT_TRUE(again) << again.GetError().mMessage;
    ASSERT_EQ(again.Value().size(), 3u);
    for (size_t i = 0; i < 3; ++i)
        EXPECT_EQ(again.Value()[i].mUserID, unjoined[i].mUserID);
    // Without the east platform's tile, link 1's end is in no tile given: unjoined
    navmesh::NavMeshFileContents westOnly = merged.Value();
    std::erase_if(westOnly.mTiles,
                  [](const navmesh::NavMeshFileTile& inTile) { return inTile.mTile.mX != 0; });
    ASSERT_EQ(westOnly.mTiles.size(), 1u);
    EXPECT_EQ(FindUnjoinedLinks(westOnly, declared).Value().size(), 4u);
    EXPECT_EQ(FindUnjoinedLinks(westOnly).Value().size(), 3u)
        << "without the declared links, not the left-out one";
}

TEST_F(BakeLinksTest, TheLinksFileErrorsNameTheFileTheLinkAndTheKey)
{
    struct Case
    {
        const char* mText;
        const char* mSays;
    };
    const Case cases[] = {
        {"[]", "not a JSON object"},
        {R"({"link": []})", "unknown key 'link'"},
        {R"({"links": {}})", "'links' must be an array"},
        {R"({"links": [3]})", "link 0: not a JSON object"},
        {R"({"links": [{"start": [0, 0, 0]}]})", "link 0: needs 'start' and 'end'"},
        {R"({"links": [{"start": [0, 0], "end": [1, 0, 0]}]})", "link 0: 'start' must be three numbers"},
        {R"({"links": [{"start": [0, 0, 0], "end": [1, 0, 1e39]}]})", "link 0: 'end' must be three numbers"},
        {R"({"links": [{"start": [0, 0, 0], "end": [1, 0, "x"]}]})", "'end' must be three numbers"},
        {R"({"links": [{"start": [0, 0, 0], "end": [1, 0, 2e6]}]})", "within the world's range"},
        {R"({"links": [{"start": [0,0,0], "end": [1,0,0]}, {"start": [0,0,0], "end": [1,0,0], "radius": 0}]})",
         "link 1: 'radius' must be a number in (0, 1000]"},
        {R"({"links": [{"start": [0, 0, 0], "end": [1, 0, 0], "area": 63}]})",
         "'area' must be a whole number"},
        {R"({"links": [{"start": [0, 0, 0], "end": [1, 0, 0], "user_id": 4294967296}]})",
         "'user_id' must be a whole number from 0 to 4294967295"},
        {R"({"links": [{"start": [0, 0, 0], "end": [1, 0, 0], "bidirectional": 1}]})",
         "'bidirectional' must be true or false"},
        {R"({"links": [{"start": [0, 0, 0], "end": [1, 0, 0], "raduis": 1}]})", "unknown key 'raduis'"},
        {"{\"links\": [", "links.json"},
    };
    for (const Case& c : cases)
    {
        const std::string path = Write("links.json", c.mText);
        Result<std::vector<navmesh::OffMeshLink>> links = LoadOffMeshLinks(path);
        ASSERT_FALSE(links) << c.mText;
        EXPECT_NE(links.GetError().mMessage.find(c.mSays), std::string::npos)
            << c.mText << " said: " << links.GetError().mMessage;
        EXPECT_NE(links.GetError().mMessage.find(path), std::string::npos) << "names the file";
    }
    EXPECT_FALSE(LoadOffMeshLinks(mFiles.Path("missing.json")));
    Result<std::vector<navmesh::OffMeshLink>> none = LoadOffMeshLinks(Write("links.json", "{}"));
    ASSERT_TRUE(none);
    EXPECT_TRUE(none.Value().empty());
}

} // namespace
} // namespace cairn::bake
