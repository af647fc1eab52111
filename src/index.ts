/**
 * The library: audio in, animated face out, all in the browser. See docs/engine.md.
 *
 *   const engine = await TalkingFaceEngine.load();                   // the model at /models/manifest.json
 *   const audio = await decodeAudio(file, engine.manifest.audio.sample_rate);
 *   const animation = await engine.animate(audio.samples);          // offline, in chunks
 *   const live = await engine.listen(await openMicrophone(), (first, frames) => draw(frames));
 */
export { TalkingFaceEngine, StreamSession, EngineDisposedError } from './engine/engine';
export { DEFAULT_CHUNK_FRAMES } from './engine/pipeline';
export type { Backend, EngineOptions, AnimateOptions, Animation, Frames, StageTimes } from './engine/engine';
export { LiveSession, type LiveOptions } from './engine/live';
export { decodeAudio, levels, AudioDecodeError, SILENT_PEAK, type DecodedAudio } from './audio/decode';
export { openMicrophone, listMicrophones, AudioCapture, MicrophoneError, type CaptureOptions, type Microphone } from './audio/capture';
export { StreamResampler, resampleAll } from './audio/resample';
export { speakStream, type PageStreamOptions } from './player/page-stream';
export { heardTime } from './player/stream-timeline';
export type { SpeechStream, MediaSpeechStream } from './player/speech-stream';
export type { SpeechStreamOptions, WrittenSpeechOptions, MediaSpeechOptions, StreamDelayOption, StreamTake } from './player/stream-options';
export type { PcmChunk } from './audio/pcm';
export { logMel, logMelFrames, logMelFramesMeyda, melFrameCount } from './audio/mel';
export { ModelLoadError, fetchManifest } from './model/artefacts';
export type { ExecutionProvider } from './encoders/onnx-model';
export { setRuntimeBase } from './encoders/ort-worker-client';
export { checkManifest, frameToMelIndex, DEFAULT_MANIFEST_URL, type Manifest } from './model/manifest';
export { ReferenceDecoder, decoderWeights, type DecoderWeights, type DecodeResult } from './attention/reference';
export { applyPose } from './pose/posing';
export { FastDecoder } from './attention/fast-decoder';
export { GpuDecoder } from './attention/gpu-decoder';
export { detectWebGPU } from './gpu/capabilities';
export { webglAvailable } from './render/software-gl';
export { loadTemplate, decodeTemplate, MM_PER_UNIT, type FaceTemplate } from './template/face-template';
export { ARKIT_NAMES, VISEME_NAMES, LIVE_LINK_FACE_COLUMNS, normaliseMorphName, type ArkitName, type VisemeName } from './avatar/names';
export { arkitBasis, JAW_OPEN_DEGREES, type ArkitBasis } from './avatar/basis';
export { BlendshapeSolver, type SolverOptions, type SolverState } from './avatar/solver';
export { AvatarWeights, frameWeights, yawPitchRoll, type BlendshapeFrames, type FrameWeights } from './avatar/weights';
export { VisemeMap, PHONE_TO_VISEME } from './avatar/visemes';
export { GltfAvatar, AvatarLoadError, type AvatarSummary, type AvatarBindOptions } from './avatar/gltf-avatar';
export { AvatarDriver, BLEND_IN_SECONDS, BLEND_OUT_SECONDS, type DrivenFrames, type DrivenLiveFrames } from './avatar/avatar-driver';
export { Blinks } from './avatar/blinks';
export { blendshapesJson, liveLinkFaceCsv, liveLinkTimecode, blendshapesGlb } from './avatar/export';
export { vrmAnimation } from './avatar/vrm-animation';
export { TalkingHeadDriver, talkingHeadAnim, talkingHeadAngles, TALKINGHEAD_SHAPES, TALKINGHEAD_HEAD, type TalkingHeadLike, type TalkingHeadOptions } from './avatar/talkinghead';
export { avatarScene, visemeAsArkit, buildAvatarGlb } from './avatar/avatar-mesh';
export { fullBodyScene, buildFullBodyAvatarGlb } from './avatar/full-body-rig';
