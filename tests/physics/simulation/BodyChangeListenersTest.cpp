// Several listeners can follow one world's body changes (a navmesh per agent profile): before, a second
// TileScheduler replaced the first one's listener and its navmesh went stale without a word.

#include "SimulationFixture.h"

#include <array>
#include <mutex>
#include <vector>

namespace cairn::test
{
using namespace cairn::physics;
namespace
{

class RecordingListener final : public BodyChangeListener
{
public:
    void OnBodyChanged(const BodyChange& inChange) override
    {
        std::lock_guard lock(mMutex); // A leaf mutex, as the contract asks
        mAdded += inChange.mKind == BodyChangeKind::Added ? 1 : 0;
    }
    int Added()
    {
        std::lock_guard lock(mMutex);
        return mAdded;
    }

private:
    std::mutex mMutex;
    int mAdded = 0;
};

} // namespace

using BodyChangeListenersTest = SimulationFixture;

TEST_F(BodyChangeListenersTest, EveryRegisteredListenerHearsOfEachChange)
{
    RecordingListener first, second;
    ASSERT_TRUE(System().AddBodyChangeListener(&first));
    ASSERT_TRUE(System().AddBodyChangeListener(&second));
    AddFloor();
    EXPECT_EQ(first.Added(), 1);
    EXPECT_EQ(second.Added(), 1);

    System().RemoveBodyChangeListener(&first);
    AddDynamic(DynamicSettings(Box(Vec3(0.5f, 0.5f, 0.5f)), Vec3(0, 3, 0)));
    EXPECT_EQ(first.Added(), 1) << "removed: hears nothing more";
    EXPECT_EQ(second.Added(), 2);
    System().RemoveBodyChangeListener(&second);
}

TEST_F(BodyChangeListenersTest, ListenersBeyondTheLimitAreRefused)
{
    std::array<RecordingListener, BodyManager::cMaxChangeListeners + 1> listeners;
    for (uint32_t i = 0; i < BodyManager::cMaxChangeListeners; ++i)
        EXPECT_TRUE(System().AddBodyChangeListener(&listeners[i]));
    EXPECT_FALSE(System().AddBodyChangeListener(&listeners.back()));
    EXPECT_FALSE(System().AddBodyChangeListener(nullptr));
    for (RecordingListener& listener : listeners)
        System().RemoveBodyChangeListener(&listener);
    EXPECT_TRUE(System().AddBodyChangeListener(&listeners.back())) << "room again";
    System().RemoveBodyChangeListener(&listeners.back());
}

} // namespace cairn::test
