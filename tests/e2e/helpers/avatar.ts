/** Avatars on a test page: one <talking-face> at a time, with an avatar. */
import type { Page } from '@playwright/test';

/**
 * Put one 320 px <talking-face avatar> (backend cpu, status hidden; avatar-facing if given) first in the page, in
 * place of any other; resolves with its ready detail's `avatar` half a second after ready (the rest's weights set,
 * then drawn), rejects with its error's message.
 */
export function addAvatarFace(page: Page, avatar: string, facing: string | null = null): Promise<unknown> {
  return page.evaluate(([a, f]) => new Promise<unknown>((resolve, reject) => {
    document.querySelectorAll('talking-face').forEach((e) => e.remove());
    const el = document.createElement('talking-face');
    Object.assign(el.style, { width: '320px', height: '320px', display: 'block' });
    el.setAttribute('backend', 'cpu');
    el.setAttribute('hide-status', '');
    el.setAttribute('avatar', a);
    if (f) el.setAttribute('avatar-facing', f);
    el.addEventListener('ready', (e) => setTimeout(() => resolve((e as CustomEvent).detail.avatar), 500));
    el.addEventListener('error', (e) => reject(new Error((e as CustomEvent).detail.message)));
    document.body.prepend(el);
  }), [avatar, facing] as const);
}
