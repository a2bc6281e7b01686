// The Walker sample: put this on a character whose bones are named as the CMU walk's joints
// (Hips, LeftUpLeg, ...) and assign human_walk_cmu.bytes; it walks forever, new every seed.
using UnityEngine;

namespace Sinmdm.Samples
{
    public sealed class WalkerSample : MonoBehaviour
    {
        public TextAsset walkModel;
        public long seed = 7;

        void Awake()
        {
            var animator = gameObject.AddComponent<SinmdmAnimator>();
            animator.model = walkModel;
            animator.seed = seed;
        }
    }
}
