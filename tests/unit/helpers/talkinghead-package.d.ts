/**
 * The part of @met4citizen/talkinghead (a devDependency: plain JavaScript, no declarations) that the unit tests
 * use: talkinghead.test.ts runs the package itself in Node (helpers/talkinghead.ts).
 */
declare module '@met4citizen/talkinghead' {
  export interface MorphTargetState {
    realtime: number | null;
    needsUpdate: boolean;
    value: number;
    applied: number;
    baseline: number | null;
  }
  export class TalkingHead {
    constructor(node: HTMLElement | null, opt?: Record<string, unknown>);
    showAvatar(avatar: { url: string; body?: 'M' | 'F'; avatarMood?: string }): Promise<void>;
    /** One step of its animation loop; in avatarOnly mode the argument is the step in ms. */
    animate(dt: number): void;
    speakAudio(r: { audio: unknown; anim?: object }, opt?: { isRaw?: boolean }): void;
    animFactory(t: object, loop?: boolean, scaleTime?: number, scaleValue?: number, noClockOffset?: boolean): { ts: number[]; vs: Record<string, (number | null)[]> };
    mtAvatar: Record<string, MorphTargetState>;
    morphs: { morphTargetDictionary: Record<string, number>; morphTargetInfluences: number[] }[];
    armature: import('three').Object3D;
    avatarHeight: number;
    animClock: number;
    animQueue: { template: { name: string }; ts: number[] }[];
    poseDelta: { props: Record<string, { x: number; y: number; z: number }> };
  }
}
