#include "broadphase/EpochReclaimer.h"

#include "broadphase/ThreadStripe.h"

namespace cairn::physics
{

std::atomic<uint32_t>& EpochReclaimer::Enter(uint64_t* outEpoch) const
{
    Stripe& stripe = const_cast<Stripe&>(mStripes[GetThreadStripe(cNumStripes)]);
    for (;;)
    {
        // seq_cst: see the header comment (register, then re-check the epoch, in one total order with the
        // updater's count check and advance)
        const uint64_t epoch = mEpoch.load(std::memory_order_seq_cst);
        std::atomic<uint32_t>& counter = stripe.mReaders[epoch & 1];
        counter.fetch_add(1, std::memory_order_seq_cst);
        if (mEpoch.load(std::memory_order_seq_cst) == epoch)
        {
            if (outEpoch != nullptr) *outEpoch = epoch;
            return counter;
        }
        // The epoch moved between the two loads: our count may be in a parity the updater already checked
        // Relaxed: we read nothing under this registration
        counter.fetch_sub(1, std::memory_order_relaxed);
    }
}

bool EpochReclaimer::TryAdvance()
{
    const uint64_t epoch = mEpoch.load(std::memory_order_seq_cst); // See the header comment
    const uint32_t previousParity = uint32_t(epoch + 1) & 1;       // Parity of epoch - 1
    for (const Stripe& stripe : mStripes)
        // seq_cst: pairs with the readers' increment and re-check; see the header comment
        if (stripe.mReaders[previousParity].load(std::memory_order_seq_cst) != 0) return false;
    mEpoch.store(epoch + 1, std::memory_order_seq_cst);
    return true;
}

} // namespace cairn::physics
