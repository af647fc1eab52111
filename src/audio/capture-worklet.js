// The capture's AudioWorklet (capture.ts): posts the mono mix of its input in blocks of `block` samples (128-sample
// render quanta gathered). Plain JavaScript, loaded as it is: from a blob: URL of this text, or as this file.
class TalkingFaceCapture extends AudioWorkletProcessor {
  constructor(options) {
    super();
    this.block = options.processorOptions.block;
    this.buffer = new Float32Array(this.block);
    this.filled = 0;
    this.running = true;
    // On 'stop': hand over the partial block, then say so; the main thread waits for 'stopped', so
    // every captured sample reaches it even if it was busy and its message queue is long.
    this.port.onmessage = (e) => {
      if (e.data !== 'stop' || !this.running) return;
      this.running = false;
      if (this.filled > 0) this.port.postMessage(this.buffer.slice(0, this.filled));
      this.port.postMessage('stopped');
    };
  }
  process(inputs) {
    if (!this.running) return false;
    const input = inputs[0];
    if (input && input.length > 0) {
      const n = input[0].length;
      for (let i = 0; i < n; i++) {
        let s = 0;
        for (let c = 0; c < input.length; c++) s += input[c][i];
        this.buffer[this.filled++] = s / input.length;
        if (this.filled === this.block) {
          this.port.postMessage(this.buffer, [this.buffer.buffer]);
          this.buffer = new Float32Array(this.block);
          this.filled = 0;
        }
      }
    }
    return true;
  }
}
registerProcessor('talking-face-capture', TalkingFaceCapture);
